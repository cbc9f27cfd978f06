//! [`AxisMap`]: which source channel (dataset or column) feeds which tilt axis, and with which
//! sign; and the default mapping used when no map is given.

use super::error::InputError;
use crate::error::{shown_list, Shown};
use crate::model::TiltAxis;
use std::fmt;
use std::path::Path;
use std::str::FromStr;

/// Sign applied to a source channel: `target = sign * source`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Sign {
    /// `target = +source`.
    Plus,
    /// `target = -source`.
    Minus,
}

impl Sign {
    /// `+1.0` or `-1.0`.
    pub fn factor(self) -> f64 {
        match self {
            Sign::Plus => 1.0,
            Sign::Minus => -1.0,
        }
    }

    /// `""` or `"-"`, as written in a map.
    fn prefix(self) -> &'static str {
        match self {
            Sign::Plus => "",
            Sign::Minus => "-",
        }
    }
}

/// One assignment `target = sign * source`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct AxisMapEntry {
    /// The tilt axis fed.
    pub target: TiltAxis,
    /// The sign.
    pub sign: Sign,
    /// The source channel name (HDF5 dataset or CSV column), case-sensitive.
    pub source: String,
}

/// A mapping from source channels to tilt axes, e.g. `theta_t=-E,eta_t=-N`.
///
/// Syntax: comma-separated entries `TARGET=[+|-]SOURCE`; `TARGET` is `theta_t`, `eta_t` or
/// `phi_t`; `SOURCE` is a channel name (no whitespace, `,` or `=`; it may not start with a
/// sign). Whitespace around tokens is ignored. Each target and each source may appear at most
/// once. Only the mapped axes are read; other channels in the file are ignored.
///
/// ```
/// use tiltnoise_core::input::{AxisMap, Sign};
/// use tiltnoise_core::model::TiltAxis;
/// let map: AxisMap = "theta_t=-LJE, eta_t=-LJN".parse().unwrap();
/// assert_eq!(map.entries()[0].target, TiltAxis::ThetaT);
/// assert_eq!(map.entries()[0].sign, Sign::Minus);
/// assert_eq!(map.entries()[0].source, "LJE");
/// assert_eq!(map.to_string(), "theta_t=-LJE,eta_t=-LJN");
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct AxisMap {
    entries: Vec<AxisMapEntry>,
}

impl AxisMap {
    /// Parses a specification; errors name `origin` "axis map".
    ///
    /// # Errors
    ///
    /// [`InputError::AxisMapSyntax`] naming the offending entry.
    pub fn parse(spec: &str) -> Result<AxisMap, InputError> {
        Self::parse_from(spec, "axis map")
    }

    /// Parses a specification; errors name `origin` (e.g. the file and attribute it came from).
    ///
    /// # Errors
    ///
    /// [`InputError::AxisMapSyntax`] naming the offending entry.
    pub fn parse_from(spec: &str, origin: &str) -> Result<AxisMap, InputError> {
        let err = |entry: &str, message: String| InputError::AxisMapSyntax {
            origin: origin.to_string(),
            spec: spec.to_string(),
            entry: entry.to_string(),
            message,
        };
        if spec.trim().is_empty() {
            return Err(err("", "empty specification".to_string()));
        }
        let mut entries: Vec<AxisMapEntry> = Vec::new();
        for raw in spec.split(',') {
            let entry = raw.trim();
            if entry.is_empty() {
                return Err(err(entry, "empty entry (stray comma?)".to_string()));
            }
            let Some((target, source)) = entry.split_once('=') else {
                return Err(err(entry, "missing `=`".to_string()));
            };
            let target = target.trim();
            let target = TiltAxis::ALL
                .into_iter()
                .find(|a| a.name() == target)
                .ok_or_else(|| {
                    err(
                        entry,
                        format!(
                            "unknown target `{}`, allowed: theta_t, eta_t, phi_t",
                            Shown(target)
                        ),
                    )
                })?;
            let source = source.trim();
            let (sign, name) = if let Some(rest) = source.strip_prefix('-') {
                (Sign::Minus, rest)
            } else if let Some(rest) = source.strip_prefix('+') {
                (Sign::Plus, rest)
            } else {
                (Sign::Plus, source)
            };
            if name.is_empty() {
                return Err(err(entry, "empty source channel name".to_string()));
            }
            if name.starts_with(['+', '-']) {
                return Err(err(
                    entry,
                    format!("source `{}` has more than one sign", Shown(name)),
                ));
            }
            if let Some(c) = name.chars().find(|c| c.is_whitespace() || *c == '=') {
                return Err(err(
                    entry,
                    format!(
                        "source `{}` contains `{}`, not allowed in a channel name",
                        Shown(name),
                        Shown(c.encode_utf8(&mut [0; 4]))
                    ),
                ));
            }
            if let Some(prev) = entries.iter().find(|e| e.target == target) {
                return Err(err(
                    entry,
                    format!(
                        "target {} is assigned twice (already {}{})",
                        target.name(),
                        prev.sign.prefix(),
                        Shown(&prev.source)
                    ),
                ));
            }
            if let Some(prev) = entries.iter().find(|e| e.source == name) {
                return Err(err(
                    entry,
                    format!(
                        "source `{}` is used twice (already for {})",
                        Shown(name),
                        prev.target.name()
                    ),
                ));
            }
            entries.push(AxisMapEntry {
                target,
                sign,
                source: name.to_string(),
            });
        }
        Ok(AxisMap { entries })
    }

    /// Builds a map from entries (no validation of duplicates beyond what [`AxisMap::parse`]
    /// would do: duplicates are rejected by [`AxisMap::parse`] only).
    pub fn from_entries(entries: Vec<AxisMapEntry>) -> AxisMap {
        AxisMap { entries }
    }

    /// The entries in the order given.
    pub fn entries(&self) -> &[AxisMapEntry] {
        &self.entries
    }
}

impl FromStr for AxisMap {
    type Err = InputError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        AxisMap::parse(s)
    }
}

impl fmt::Display for AxisMap {
    /// The canonical form `theta_t=-E,eta_t=-N` (parses back to an equal map).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (k, e) in self.entries.iter().enumerate() {
            if k > 0 {
                f.write_str(",")?;
            }
            write!(f, "{}={}{}", e.target.name(), e.sign.prefix(), e.source)?;
        }
        Ok(())
    }
}

/// Where a map came from, for provenance notes and error messages.
#[derive(Debug, Clone, Copy)]
pub enum MapOrigin<'a> {
    /// [`super::ReadOptions::axis_map`].
    Options(&'a AxisMap),
    /// File metadata (`axis_map` attribute or `# axes:` line); the string describes where.
    File(&'a AxisMap, &'a str),
    /// Neither: the default mapping.
    Default,
}

/// One resolved channel: `axis = sign * available[index]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Mapped {
    pub axis: TiltAxis,
    pub sign: Sign,
    pub source: String,
    pub index: usize,
}

/// The result of resolving a map against the channels a file has.
#[derive(Debug, Clone)]
pub struct Resolved {
    /// In canonical axis order (theta_t, eta_t, phi_t).
    pub channels: Vec<Mapped>,
    /// The effective map in canonical syntax.
    pub map: AxisMap,
    /// Provenance notes.
    pub notes: Vec<String>,
}

/// The default assignment of a channel name: tiltnoise names map to themselves; the
/// seismological rotation channels `E`, `N`, `Z` (or SEED rotation codes `?JE`, `?JN`, `?JZ`)
/// map with lab x = East, y = North, z = Up and the minus sign of `t = -(floor rotation)`; a
/// full SEED code `NET.STA.LOC.CHA` maps as its channel code `CHA` does.
pub fn default_assignment(name: &str) -> Option<(TiltAxis, Sign)> {
    if let Some(a) = TiltAxis::ALL.into_iter().find(|a| a.name() == name) {
        return Some((a, Sign::Plus));
    }
    // A full SEED code `NET.STA.LOC.CHA` is judged by its channel code.
    let parts: Vec<&str> = name.split('.').collect();
    let name = match parts.as_slice() {
        [_, _, _, cha] => cha,
        _ => name,
    };
    let orientation = match name.as_bytes() {
        [o] => *o,
        [band, b'J', o] if band.is_ascii_uppercase() => *o,
        _ => return None,
    };
    match orientation {
        b'E' => Some((TiltAxis::ThetaT, Sign::Minus)),
        b'N' => Some((TiltAxis::EtaT, Sign::Minus)),
        b'Z' => Some((TiltAxis::PhiT, Sign::Minus)),
        _ => None,
    }
}

/// Text of the default-mapping note in the provenance.
pub const DEFAULT_MAP_NOTE: &str = "axis map: default (assumption: lab x = East, \
     y = North, z = Up, so theta_t = -E, eta_t = -N, phi_t = -Z for rotation channels E/N/Z or \
     ?JE/?JN/?JZ; theta_t/eta_t/phi_t channels used as they are); override with an explicit \
     axis map";

/// Resolves `origin` against the channel names `available` of `path`. `kind` is `dataset` or
/// `column`.
pub fn resolve(
    path: &Path,
    available: &[String],
    origin: MapOrigin<'_>,
    kind: &'static str,
) -> Result<Resolved, InputError> {
    let mut notes = Vec::new();
    let mut channels: Vec<Mapped> = Vec::new();
    match origin {
        MapOrigin::Options(map) | MapOrigin::File(map, _) => {
            match origin {
                MapOrigin::File(_, from) => notes.push(format!(
                    "axis map: {} (from {from})",
                    Shown(&map.to_string())
                )),
                _ => notes.push(format!(
                    "axis map: {} (given explicitly)",
                    Shown(&map.to_string())
                )),
            }
            for e in map.entries() {
                let index = available
                    .iter()
                    .position(|n| *n == e.source)
                    .ok_or_else(|| InputError::AxisMapSource {
                        path: path.to_path_buf(),
                        target: e.target.name(),
                        kind,
                        source_name: e.source.clone(),
                        available: shown_list(available),
                    })?;
                channels.push(Mapped {
                    axis: e.target,
                    sign: e.sign,
                    source: e.source.clone(),
                    index,
                });
            }
        }
        MapOrigin::Default => {
            notes.push(DEFAULT_MAP_NOTE.to_string());
            for axis in TiltAxis::ALL {
                let cands: Vec<(usize, Sign)> = available
                    .iter()
                    .enumerate()
                    .filter_map(|(i, n)| match default_assignment(n) {
                        Some((a, s)) if a == axis => Some((i, s)),
                        _ => None,
                    })
                    .collect();
                match cands.as_slice() {
                    [] => {}
                    [(index, sign)] => channels.push(Mapped {
                        axis,
                        sign: *sign,
                        source: available[*index].clone(),
                        index: *index,
                    }),
                    more => {
                        let names: Vec<&str> =
                            more.iter().map(|(i, _)| available[*i].as_str()).collect();
                        return Err(InputError::AmbiguousAxis {
                            path: path.to_path_buf(),
                            kind,
                            axis: axis.name(),
                            candidates: shown_list(&names),
                            first: names[0].to_string(),
                        });
                    }
                }
            }
            if channels.is_empty() {
                return Err(InputError::NoAxes {
                    path: path.to_path_buf(),
                    kind,
                    found: if available.is_empty() {
                        "(none)".to_string()
                    } else {
                        shown_list(available)
                    },
                });
            }
        }
    }
    channels.sort_by_key(|m| m.axis.index());
    let ignored: Vec<&str> = available
        .iter()
        .enumerate()
        .filter(|(i, _)| !channels.iter().any(|m| m.index == *i))
        .map(|(_, n)| n.as_str())
        .collect();
    if !ignored.is_empty() {
        notes.push(format!("ignored {kind}s: {}", shown_list(&ignored)));
    }
    let map = AxisMap::from_entries(
        channels
            .iter()
            .map(|m| AxisMapEntry {
                target: m.axis,
                sign: m.sign,
                source: m.source.clone(),
            })
            .collect(),
    );
    Ok(Resolved {
        channels,
        map,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_assignments() {
        assert_eq!(
            default_assignment("theta_t"),
            Some((TiltAxis::ThetaT, Sign::Plus))
        );
        assert_eq!(
            default_assignment("E"),
            Some((TiltAxis::ThetaT, Sign::Minus))
        );
        assert_eq!(
            default_assignment("LJN"),
            Some((TiltAxis::EtaT, Sign::Minus))
        );
        assert_eq!(
            default_assignment("BJZ"),
            Some((TiltAxis::PhiT, Sign::Minus))
        );
        assert_eq!(
            default_assignment("BW.ROMY.11.LJE"),
            Some((TiltAxis::ThetaT, Sign::Minus))
        );
        assert_eq!(default_assignment("BW.ROMY.11.LHE"), None);
        assert_eq!(default_assignment("LHN"), None);
        assert_eq!(default_assignment("lJN"), None);
        assert_eq!(default_assignment("X"), None);
    }

    #[test]
    fn parse_errors() {
        for bad in [
            "",
            "theta_t",
            "theta_t=",
            "theta_t=--E",
            "x_t=E",
            "theta_t=E,theta_t=N",
            "theta_t=E,eta_t=-E",
            "theta_t=E,",
            "theta_t=E F",
        ] {
            assert!(AxisMap::parse(bad).is_err(), "{bad}");
        }
        let m = AxisMap::parse(" eta_t = +N , theta_t=-E").unwrap();
        assert_eq!(m.to_string(), "eta_t=N,theta_t=-E");
    }
}

//! [`AxisMap`]: which source channel (dataset or column) feeds which input of the floor's
//! motion (a tilt axis or a translation axis), and with which sign; and the default mapping used
//! when no map is given, which tells rotation from translation channels by their unit or their
//! SEED instrument code.

use super::error::InputError;
use super::unit::Motion;
use crate::error::{shown_list, Shown};
use crate::model::{Input, TiltAxis, TranslationAxis};
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

/// The inputs an axis map may feed, in canonical order: the tilt axes, then the translations.
pub fn ground_inputs() -> Vec<Input> {
    Input::all_ground()
}

/// Position of a ground input in [`ground_inputs`] (theta_t 0 .. phi_t 2, x_t 3 .. z_t 5); the
/// order of every record's channels.
pub fn ground_index(input: Input) -> usize {
    match input {
        Input::Tilt(a) => a.index(),
        Input::Translation(t) => 3 + t.index(),
        Input::Force(f) => 6 + f.index(),
    }
}

/// What a ground input is: a rotation (tilt) or a translation.
pub fn motion_of(input: Input) -> Motion {
    match input {
        Input::Translation(_) => Motion::Translation,
        _ => Motion::Rotation,
    }
}

/// One assignment `target = sign * source`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct AxisMapEntry {
    /// The input fed: a tilt axis or a floor translation.
    pub target: Input,
    /// The sign.
    pub sign: Sign,
    /// The source channel name (HDF5 dataset or CSV column), case-sensitive.
    pub source: String,
}

/// A mapping from source channels to the floor's inputs, e.g. `theta_t=-E,eta_t=-N` or
/// `theta_t=-LJE,eta_t=-LJN,x_t=LHE,y_t=LHN`.
///
/// Syntax: comma-separated entries `TARGET=[+|-]SOURCE`; `TARGET` is a tilt axis `theta_t`,
/// `eta_t`, `phi_t` or a translation `x_t`, `y_t`, `z_t`; `SOURCE` is a channel name (no whitespace, `,` or `=`; it may not start with a
/// sign). Whitespace around tokens is ignored. Each target and each source may appear at most
/// once. Only the mapped axes are read; other channels in the file are ignored.
///
/// ```
/// use tiltnoise_core::input::{AxisMap, Sign};
/// use tiltnoise_core::model::{Input, TiltAxis};
/// let map: AxisMap = "theta_t=-LJE, eta_t=-LJN".parse().unwrap();
/// assert_eq!(map.entries()[0].target, Input::Tilt(TiltAxis::ThetaT));
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
            let target = ground_inputs()
                .into_iter()
                .find(|a| a.name() == target)
                .ok_or_else(|| {
                    err(
                        entry,
                        format!(
                            "unknown target `{}`, allowed: theta_t, eta_t, phi_t, x_t, y_t, z_t",
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

/// One resolved channel: `input = sign * available[index]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Mapped {
    /// The input fed: a tilt axis or a floor translation.
    pub input: Input,
    pub sign: Sign,
    pub source: String,
    pub index: usize,
}

impl Mapped {
    /// The tilt axis fed, if it is one.
    pub fn tilt_axis(&self) -> Option<TiltAxis> {
        match self.input {
            Input::Tilt(a) => Some(a),
            _ => None,
        }
    }

    /// The translation fed, if it is one.
    pub fn translation_axis(&self) -> Option<TranslationAxis> {
        match self.input {
            Input::Translation(t) => Some(t),
            _ => None,
        }
    }
}

/// The result of resolving a map against the channels a file has.
#[derive(Debug, Clone)]
pub struct Resolved {
    /// In canonical order ([`ground_inputs`]: theta_t, eta_t, phi_t, x_t, y_t, z_t).
    pub channels: Vec<Mapped>,
    /// The effective map in canonical syntax.
    pub map: AxisMap,
    /// Provenance notes.
    pub notes: Vec<String>,
}

/// The channel code `CHA` of a full SEED code `NET.STA.LOC.CHA`, else the name itself.
fn channel_code(name: &str) -> &str {
    match name.split('.').collect::<Vec<_>>().as_slice() {
        [_, _, _, cha] => cha,
        _ => name,
    }
}

/// What a SEED channel code (`CHA`, or a full code `NET.STA.LOC.CHA`) says its sensor measures,
/// by its instrument code (the second letter, after an upper-case band code): `J` (rotation
/// sensor) and `A` (tiltmeter) a rotation; `H`, `L` (high- and low-gain seismometer), `N`
/// (accelerometer) and `P` (geophone) a translation. `None` for other names.
pub fn instrument_motion(name: &str) -> Option<Motion> {
    match channel_code(name).as_bytes() {
        [band, instrument, _] if band.is_ascii_uppercase() => match instrument {
            b'J' | b'A' => Some(Motion::Rotation),
            b'H' | b'L' | b'N' | b'P' => Some(Motion::Translation),
            _ => None,
        },
        _ => None,
    }
}

/// What each channel of `available` (of `path`) measures: the motion of its unit where one is
/// stated (`units[i]`), else what its SEED instrument code says ([`instrument_motion`]), else
/// nothing known.
///
/// # Errors
///
/// [`InputError::ChannelUnit`] for a unit that contradicts the instrument code (`LJE` in m/s^2,
/// `LHE` in rad/s).
pub fn channel_motions(
    path: &Path,
    available: &[String],
    units: &[Option<Motion>],
) -> Result<Vec<Option<Motion>>, InputError> {
    available
        .iter()
        .zip(units)
        .map(|(name, unit)| match (unit, instrument_motion(name)) {
            (Some(u), Some(code)) if *u != code => Err(InputError::ChannelUnit {
                path: path.to_path_buf(),
                channel: name.clone(),
                message: format!(
                    "has a unit of {}, but its SEED instrument code `{}` is that of a {} sensor; \
                     allowed: a unit of {} ({})",
                    u.name(),
                    char::from(channel_code(name).as_bytes()[1]),
                    code.name(),
                    code.name(),
                    match code {
                        Motion::Rotation => "rad or rad/s",
                        Motion::Translation => "m, m/s or m/s^2",
                    }
                )
                .into(),
            }),
            (Some(u), _) => Ok(Some(*u)),
            (None, code) => Ok(code),
        })
        .collect()
}

/// The default assignment of a channel name, given what its unit (or instrument code) says it
/// measures (`motion`, `None` when nothing does): tiltnoise names (`theta_t` .. `z_t`) map to
/// themselves; a channel oriented `E`, `N` or `Z` (the bare letter, or the last letter of a
/// SEED code) maps with lab x = East, y = North, z = Up: a rotation (the bare letter without a
/// translation unit, or a SEED rotation-sensor code `?JE`) to `theta_t = -E`, `eta_t = -N`,
/// `phi_t = -Z` (the minus of `t = -(floor rotation)`), a translation (a unit of length,
/// velocity or acceleration, or a seismometer or accelerometer code such as `LHE`, `BHN`,
/// `HNZ`) to `x_t = E`, `y_t = N`, `z_t = Z`. A full SEED code maps as its channel code does.
pub fn default_assignment(name: &str, motion: Option<Motion>) -> Option<(Input, Sign)> {
    if let Some(a) = ground_inputs().into_iter().find(|a| a.name() == name) {
        return Some((a, Sign::Plus));
    }
    let code = channel_code(name);
    let (orientation, motion) = match code.as_bytes() {
        [o] => (*o, motion.unwrap_or(Motion::Rotation)),
        [band, b'J', o] if band.is_ascii_uppercase() => (*o, Motion::Rotation),
        [_, _, o] if instrument_motion(code) == Some(Motion::Translation) => {
            (*o, Motion::Translation)
        }
        _ => return None,
    };
    let axis = match orientation {
        b'E' => 0,
        b'N' => 1,
        b'Z' => 2,
        _ => return None,
    };
    Some(match motion {
        Motion::Rotation => (Input::Tilt(TiltAxis::ALL[axis]), Sign::Minus),
        Motion::Translation => (Input::Translation(TranslationAxis::ALL[axis]), Sign::Plus),
    })
}

/// Text of the default-mapping note in the provenance.
pub const DEFAULT_MAP_NOTE: &str = "axis map: default (assumption: lab x = East, \
     y = North, z = Up, so theta_t = -E, eta_t = -N, phi_t = -Z for rotation channels E/N/Z or \
     ?JE/?JN/?JZ, and x_t = E, y_t = N, z_t = Z for translation channels (a unit of length, \
     velocity or acceleration, or a seismometer or accelerometer code such as LHE, BHN, HNZ); \
     theta_t .. z_t channels used as they are); override with an explicit axis map";

/// Resolves `origin` against the channel names `available` of `path`, of which `motions` says
/// what each measures where its unit or instrument code says it ([`channel_motions`]). `kind`
/// is `dataset` or `column`.
///
/// # Errors
///
/// As [`AxisMap`] resolution fails: a source the file does not have, several channels for one
/// input, no channel at all under the default mapping, or an explicit target of the other
/// motion than its channel's ([`InputError::ChannelMotion`]).
pub fn resolve(
    path: &Path,
    available: &[String],
    motions: &[Option<Motion>],
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
                let target = motion_of(e.target);
                if let Some(motion) = motions.get(index).copied().flatten() {
                    if motion != target {
                        return Err(InputError::ChannelMotion {
                            path: path.to_path_buf(),
                            kind,
                            channel: e.source.clone(),
                            target: e.target,
                            motion,
                        });
                    }
                }
                channels.push(Mapped {
                    input: e.target,
                    sign: e.sign,
                    source: e.source.clone(),
                    index,
                });
            }
        }
        MapOrigin::Default => {
            notes.push(DEFAULT_MAP_NOTE.to_string());
            for input in ground_inputs() {
                let cands: Vec<(usize, Sign)> = available
                    .iter()
                    .enumerate()
                    .filter_map(|(i, n)| {
                        match default_assignment(n, motions.get(i).copied().flatten()) {
                            Some((a, s)) if a == input => Some((i, s)),
                            _ => None,
                        }
                    })
                    .collect();
                match cands.as_slice() {
                    [] => {}
                    [(index, sign)] => channels.push(Mapped {
                        input,
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
                            axis: input.name(),
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
    channels.sort_by_key(|m| ground_index(m.input));
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
                target: m.input,
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
        use TiltAxis::*;
        use TranslationAxis::*;
        let tilt = |a| Some((Input::Tilt(a), Sign::Minus));
        let translation = |t| Some((Input::Translation(t), Sign::Plus));
        let rotation = Some(Motion::Rotation);
        let moving = Some(Motion::Translation);
        assert_eq!(
            default_assignment("theta_t", None),
            Some((Input::Tilt(ThetaT), Sign::Plus))
        );
        assert_eq!(
            default_assignment("y_t", moving),
            Some((Input::Translation(YT), Sign::Plus))
        );
        // Bare letters stay rotations unless their unit says translation.
        assert_eq!(default_assignment("E", None), tilt(ThetaT));
        assert_eq!(default_assignment("E", rotation), tilt(ThetaT));
        assert_eq!(default_assignment("E", moving), translation(XT));
        assert_eq!(default_assignment("N", moving), translation(YT));
        assert_eq!(default_assignment("LJN", None), tilt(EtaT));
        assert_eq!(default_assignment("BJZ", None), tilt(PhiT));
        assert_eq!(default_assignment("BW.ROMY.11.LJE", None), tilt(ThetaT));
        // Seismometers, accelerometers and geophones are translations by their code alone.
        assert_eq!(default_assignment("BW.ROMY.11.LHE", None), translation(XT));
        assert_eq!(default_assignment("BHN", None), translation(YT));
        assert_eq!(default_assignment("HNZ", moving), translation(ZT));
        assert_eq!(default_assignment("EPE", None), translation(XT));
        // A code that says neither needs its unit, and then only bare letters map.
        assert_eq!(default_assignment("LXE", moving), None);
        assert_eq!(default_assignment("LH1", None), None);
        assert_eq!(default_assignment("lJN", None), None);
        assert_eq!(default_assignment("X", None), None);
        assert_eq!(instrument_motion("BW.ROMY.11.LAN"), Some(Motion::Rotation));
        assert_eq!(instrument_motion("LHZ"), Some(Motion::Translation));
        assert_eq!(instrument_motion("E"), None);
    }

    #[test]
    fn parse_errors() {
        for bad in [
            "",
            "theta_t",
            "theta_t=",
            "theta_t=--E",
            "u_t=E",
            "x_t=E,x_t=N",
            "theta_t=E,theta_t=N",
            "theta_t=E,eta_t=-E",
            "theta_t=E,",
            "theta_t=E F",
        ] {
            assert!(AxisMap::parse(bad).is_err(), "{bad}");
        }
        let m = AxisMap::parse(" eta_t = +N , theta_t=-E").unwrap();
        assert_eq!(m.to_string(), "eta_t=N,theta_t=-E");
        let m = AxisMap::parse("theta_t=-LJE,x_t=LHE").unwrap();
        assert_eq!(
            m.entries()[1].target,
            Input::Translation(TranslationAxis::XT)
        );
    }
}

//! Measured mode visibilities: the CSV format of `fit --visibility`, and the model's value of
//! each ratio with its derivative with respect to a parameter.
//!
//! A visibility is the signed ratio of mode `nu_k`'s component in one observable to its
//! component in a reference observable: for an undamped mode the shape is real, so the ratio
//! is real, and its sign is the relative phase (0 or pi) of the mode's peaks in the two
//! channels ([`crate::modes`], which labels the modes by overlap with the symmetric pendulum's).
//! A ratio the symmetric model forbids (nu_6 in Y, say) is a valid measurement: it is what
//! determines an offset along x.
//!
//! Format (documented for users in `docs/fit.md`), CSV as [`crate::csv_text`] reads it: `#`
//! starts a comment line; the first other line is the header `mode,observable,reference,ratio`
//! or `mode,observable,reference,ratio,sigma`; then one row per measured ratio, in any order.
//! `mode` is the label 1..8 of nu_k; `observable` and `reference` are two different names of
//! `X, Y, Z, theta, eta, phi, phi_a`; `ratio` is finite, of either sign, with magnitude at most
//! [`MAX_RATIO`] (unit: the observable's per the reference's, m/m, rad/rad, m/rad or rad/m);
//! `sigma`, when present and not empty, is the one-standard-deviation error of the ratio
//! (from 1e-40 to 2e6, [`crate::limits::VISIBILITY_SIGMA_RANGE`]). When it is absent the sigma is half a unit of the last printed digit of
//! `ratio`. Each (mode, observable, reference) at most once.

use super::measured::{half_last_digit, SigmaSource};
use super::FitError;
use crate::csv_text::{line_text, CsvRecords};
use crate::error::Shown;
use crate::limits::VISIBILITY_SIGMAS;
use crate::model::{Mat8, Observable, ObservationMatrix};
use crate::modes::NormalModes;

// The largest error of a ratio spans the whole range of ratios (limits::VISIBILITY_SIGMA_RANGE).
const _: () = assert!(crate::limits::VISIBILITY_SIGMA_RANGE.1 == 2.0 * MAX_RATIO);

/// The largest magnitude of a measured ratio: a mode a million times stronger in one channel
/// than in its reference is not measured against that reference (choose the stronger channel
/// as the reference); larger values would also leave the ratio's derivative meaningless.
pub const MAX_RATIO: f64 = 1e6;

/// The header of the format, as in error messages.
pub const HEADER: &str = "mode,observable,reference,ratio[,sigma]";

/// One measured visibility.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MeasuredVisibility {
    /// Label of the mode, 1..=8 (nu_k).
    pub mode: usize,
    /// The observable whose component is measured.
    pub observable: Observable,
    /// The observable it is measured against.
    pub reference: Observable,
    /// Signed ratio of the two components.
    pub ratio: f64,
    /// One-standard-deviation error of the ratio, > 0.
    pub sigma: f64,
    /// Where `sigma` came from.
    pub sigma_source: SigmaSource,
}

/// A set of measured visibilities, sorted by (mode, observable, reference).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Visibilities {
    /// The ratios.
    pub items: Vec<MeasuredVisibility>,
    /// Where they came from (the file name).
    pub origin: String,
}

impl Visibilities {
    /// No visibility (a fit to frequencies alone).
    pub fn none() -> Visibilities {
        Visibilities {
            items: Vec::new(),
            origin: String::new(),
        }
    }

    /// Parses and validates the CSV text; `origin` names it in error messages. (Files are
    /// read by `tiltnoise_io::read_visibilities`.)
    pub fn parse(text: &str, origin: &str) -> Result<Visibilities, FitError> {
        let fail = |line: Option<usize>, message: String| FitError::Visibility {
            origin: match line {
                Some(n) => format!("{origin}, line {n}"),
                None => origin.to_string(),
            },
            message,
        };
        let mut records = CsvRecords::from_text(text);
        let next = |records: &mut CsvRecords<&[u8]>| {
            records
                .next_record()
                .map(|r| r.map(|(n, cells)| (n, cells.into_iter().map(str::to_owned).collect())))
                .map_err(|e| fail(e.line(), e.to_string()))
        };
        let Some((hline, columns)): Option<(usize, Vec<String>)> = next(&mut records)? else {
            return Err(fail(None, format!("no header line; expected `{HEADER}`")));
        };
        let with_sigma = match columns.iter().map(String::as_str).collect::<Vec<_>>()[..] {
            ["mode", "observable", "reference", "ratio"] => false,
            ["mode", "observable", "reference", "ratio", "sigma"] => true,
            _ => {
                return Err(fail(
                    Some(hline),
                    format!(
                        "header `{}`; allowed: `{HEADER}`",
                        Shown(line_text(text, hline))
                    ),
                ))
            }
        };
        let n_columns = columns.len();
        let mut items: Vec<MeasuredVisibility> = Vec::new();
        while let Some((n, cells)) = next(&mut records)? {
            if cells.len() != n_columns {
                return Err(fail(
                    Some(n),
                    format!(
                        "`{}` has {} fields, the header has {n_columns}",
                        Shown(line_text(text, n)),
                        cells.len()
                    ),
                ));
            }
            let v = parse_row(&cells, with_sigma).map_err(|m| fail(Some(n), m))?;
            if items.iter().any(|w| {
                w.mode == v.mode && w.observable == v.observable && w.reference == v.reference
            }) {
                return Err(fail(
                    Some(n),
                    format!(
                        "nu_{} {}/{} is listed twice; give each ratio once",
                        v.mode,
                        v.observable.name(),
                        v.reference.name()
                    ),
                ));
            }
            items.push(v);
        }
        if items.is_empty() {
            return Err(fail(
                None,
                format!("no visibility; need at least one row `{HEADER}`"),
            ));
        }
        items.sort_by_key(|v| (v.mode, v.observable.index(), v.reference.index()));
        Ok(Visibilities {
            items,
            origin: origin.to_string(),
        })
    }

    /// The CSV text of the format above, with a sigma column and `comment` lines first.
    pub fn to_csv(&self, comment: &[String]) -> String {
        let mut s: String = comment.iter().map(|c| format!("# {c}\n")).collect();
        s.push_str("mode,observable,reference,ratio,sigma\n");
        for v in &self.items {
            s.push_str(&format!(
                "{},{},{},{:e},{:e}\n",
                v.mode,
                v.observable.name(),
                v.reference.name(),
                v.ratio,
                v.sigma
            ));
        }
        s
    }
}

/// One data row (as many cells as the header), or what is wrong with it.
fn parse_row(cells: &[String], with_sigma: bool) -> Result<MeasuredVisibility, String> {
    let mode: usize = cells[0]
        .parse()
        .ok()
        .filter(|m| (1..=8).contains(m))
        .ok_or_else(|| {
            format!(
                "mode `{}` is not allowed: must be an integer 1..8 (nu_k)",
                Shown(&cells[0])
            )
        })?;
    let obs = observable("observable", &cells[1])?;
    let reference = observable("reference", &cells[2])?;
    if obs == reference {
        return Err(format!(
            "observable and reference are both `{}`: a ratio to itself is 1 and \
             measures nothing",
            obs.name()
        ));
    }
    let ratio = cells[3]
        .parse::<f64>()
        .ok()
        .filter(|r| r.is_finite() && r.abs() <= MAX_RATIO)
        .ok_or_else(|| {
            format!(
                "ratio `{}` of nu_{mode} {}/{} is not allowed: must be a finite \
                 number of either sign, |ratio| <= {MAX_RATIO:e}",
                Shown(&cells[3]),
                obs.name(),
                reference.name()
            )
        })?;
    let (sigma, sigma_source) = match with_sigma && !cells[4].is_empty() {
        true => (
            cells[4]
                .parse::<f64>()
                .ok()
                .filter(|s| VISIBILITY_SIGMAS.admits(*s))
                .ok_or_else(|| {
                    format!(
                        "sigma `{}` of nu_{mode} {}/{} is not allowed: must be {} (or \
                         empty: half the last digit of ratio)",
                        Shown(&cells[4]),
                        obs.name(),
                        reference.name(),
                        VISIBILITY_SIGMAS.allowed("")
                    )
                })?,
            SigmaSource::File,
        ),
        false => (half_last_digit(&cells[3]), SigmaSource::Digits),
    };
    if !VISIBILITY_SIGMAS.admits(sigma) {
        return Err(format!(
            "the sigma of nu_{mode} {}/{} from the digits of `{}` is {sigma:e}, not {}: \
             give a sigma column",
            obs.name(),
            reference.name(),
            Shown(&cells[3]),
            VISIBILITY_SIGMAS.allowed("")
        ));
    }
    Ok(MeasuredVisibility {
        mode,
        observable: obs,
        reference,
        ratio,
        sigma,
        sigma_source,
    })
}

/// The observable named in a cell of column `what`.
fn observable(what: &str, cell: &str) -> Result<Observable, String> {
    Observable::from_name(cell).ok_or_else(|| {
        format!(
            "{what} `{}` is not an observable; allowed: {}",
            Shown(cell),
            Observable::ALL.map(Observable::name).join(", ")
        )
    })
}

/// Position in `modes.modes` of the mode labelled `nu_label`.
pub fn position_of(modes: &NormalModes, label: usize) -> Option<usize> {
    modes.modes.iter().position(|m| m.index == label)
}

/// The model's ratio of `v` in `modes` and its derivative for the matrix changes `dm`, `dk`,
/// `dc` (per unit of a parameter): `a = C x` with `x` the mass-normalized shape, `da = C dx +
/// dC x` ([`NormalModes::shape_derivative`]), `d(a_o / a_r) = (da_o - ratio da_r) / a_r`.
/// `None` for the ratio when the model's mode has no component in the reference.
pub fn model_ratio(
    modes: &NormalModes,
    observation: &ObservationMatrix,
    v: &MeasuredVisibility,
    derivatives: &[(Mat8, Mat8, ObservationMatrix)],
) -> Option<(f64, Vec<f64>)> {
    let k = position_of(modes, v.mode)?;
    let mode = &modes.modes[k];
    let (o, r) = (v.observable.index(), v.reference.index());
    let a_r = mode.observable_amplitude[r];
    if a_r == 0.0 {
        return None;
    }
    let ratio = mode.observable_amplitude[o] / a_r;
    let slopes = derivatives
        .iter()
        .map(|(dm, dk, dc)| {
            let dx = modes.shape_derivative(k, dm, dk);
            let da = observation * dx + dc * mode.shape;
            (da[o] - ratio * da[r]) / a_r
        })
        .collect();
    Some((ratio, slopes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_with_and_without_sigma() {
        let v = Visibilities::parse(
            "# a comment\nmode,observable,reference,ratio,sigma\n6,Y,X,-3.8e-3,1e-4\n2,Y,X,3.2,\n",
            "t.csv",
        )
        .unwrap();
        assert_eq!(v.items.len(), 2);
        assert_eq!(v.items[0].mode, 2);
        assert_eq!(v.items[0].sigma, 0.05);
        assert_eq!(v.items[0].sigma_source, SigmaSource::Digits);
        assert_eq!(v.items[1].ratio, -3.8e-3);
        assert_eq!(v.items[1].sigma, 1e-4);
        let again = Visibilities::parse(&v.to_csv(&["x".into()]), "again").unwrap();
        let key = |v: &MeasuredVisibility| (v.mode, v.observable, v.reference, v.ratio, v.sigma);
        assert_eq!(
            again.items.iter().map(key).collect::<Vec<_>>(),
            v.items.iter().map(key).collect::<Vec<_>>()
        );
    }

    #[test]
    fn bad_input_names_the_line_and_the_value() {
        let header = "mode,observable,reference,ratio,sigma\n";
        for (body, needle) in [
            ("9,Y,X,0.1,0.01\n", "mode `9`"),
            ("6,W,X,0.1,0.01\n", "observable `W`"),
            ("6,Y,Q,0.1,0.01\n", "reference `Q`"),
            ("6,Y,Y,0.1,0.01\n", "both `Y`"),
            ("6,Y,X,nan,0.01\n", "ratio `nan`"),
            ("6,Y,X,inf,0.01\n", "ratio `inf`"),
            ("6,Y,X,2e6,0.01\n", "ratio `2e6`"),
            ("6,Y,X,0.1,-1\n", "sigma `-1`"),
            ("6,Y,X,0.1,0\n", "sigma `0`"),
            ("6,Y,X,0.1,1e-310\n", "sigma `1e-310`"),
            ("6,Y,X,0.1,9e-41\n", "from 1e-40 to 2e6"),
            ("6,Y,X,0.1,3e6\n", "sigma `3e6`"),
            ("6,Y,X,1e-300,\n", "from the digits of `1e-300`"),
            ("6,Y,X,0.1\n", "has 4 fields"),
            ("6,Y,X,0.1,0.01\n6,Y,X,0.2,0.01\n", "listed twice"),
            ("", "no visibility"),
        ] {
            let err = Visibilities::parse(&format!("{header}{body}"), "v.csv").unwrap_err();
            let msg = err.to_string();
            assert!(msg.contains("v.csv") && msg.contains(needle), "{msg}");
            assert!(!msg.contains('\n'), "{msg}");
        }
        let err = Visibilities::parse("mode,obs,ref,ratio\n", "v.csv").unwrap_err();
        assert!(err.to_string().contains(HEADER), "{err}");
    }
}

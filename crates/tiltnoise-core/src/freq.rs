//! Frequency grids: log-spaced grids from `FLO:N:FHI` and the default grid that adds points
//! around every resonance so that no peak is missed. Frequency files are read by
//! `tiltnoise_io::read_freq_file`.
//!
//! All frequencies are in Hz. A grid has at most [`MAX_GRID_POINTS`] points. Depends on
//! `modes` (for resonance placement), `error` and `limits` only.

use crate::error::{FreqError, Num, Shown};
use crate::limits::{check_count, MAX_FREQUENCY_HZ, MAX_GRID_POINTS};
use crate::model::Model;
use crate::modes::NormalModes;
use crate::option_key::OptionKey;

/// Lower end of the default grid (Hz): 0.1 mHz, below the torsion modes.
pub const DEFAULT_F_LO_HZ: f64 = 1e-4;
/// Upper end of the default grid (Hz): above the bouncing modes.
pub const DEFAULT_F_HI_HZ: f64 = 30.0;
/// Log-spaced points of the default grid before resonance refinement.
pub const DEFAULT_POINTS: usize = 2000;
/// Relative offsets `f_k (1 +/- x)` added around an undamped resonance: they bracket the pole
/// down to 1e-6, where an undamped peak is 5e5 times its off-resonance scale, and never hit it.
const UNDAMPED_OFFSETS: [f64; 11] = [
    3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7,
];
/// Points across a damped resonance, in units of its half-width at half power `phi_k / 2`.
const DAMPED_WIDTHS: [f64; 9] = [0.0, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0];

/// Most points [`refine_around_modes`] adds per mode (both sides of every offset and width).
const REFINEMENT_POINTS_PER_MODE: usize = 2 * (UNDAMPED_OFFSETS.len() + DAMPED_WIDTHS.len());

// The refined default grid (eight modes) stays within the grid limit.
const _: () = assert!(DEFAULT_POINTS + 8 * REFINEMENT_POINTS_PER_MODE <= MAX_GRID_POINTS);

/// What a grid's size is counted in, for messages.
const POINTS: &str = "frequency points";

/// `n` log-spaced frequencies from `lo` to `hi` inclusive (`n = 1` gives `[lo]`), at most
/// [`MAX_GRID_POINTS`].
pub fn log_grid(lo: f64, hi: f64, n: usize) -> Result<Vec<f64>, FreqError> {
    Ok(LogGrid::new(lo, hi, n, MAX_GRID_POINTS)?.block(0, n))
}

/// A log-spaced grid of `len()` frequencies from `lo_hz()` to `hi_hz()` inclusive, each point
/// computed when asked for: a grid too large to hold (`tf` streams up to
/// [`crate::limits::MAX_STREAMED_GRID_POINTS`]) is evaluated and written block by block, with the points of
/// [`log_grid`] to the last bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogGrid {
    lo: f64,
    hi: f64,
    n: usize,
}

impl LogGrid {
    /// The grid `lo:n:hi` (Hz, count, Hz), refused over `limit` points, unless
    /// `0 < lo <= hi <= MAX_FREQUENCY_HZ`, both finite, and `n >= 1`.
    pub fn new(lo: f64, hi: f64, n: usize, limit: usize) -> Result<LogGrid, FreqError> {
        let spec = || format!("log grid {}:{n}:{}", Num(lo), Num(hi));
        check_count(spec, n as f64, POINTS, limit)?;
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi >= lo && n >= 1) {
            return Err(FreqError::Spec {
                origin: spec().into(),
                message: "need 0 < FLO <= FHI, both finite, and N >= 1".into(),
            });
        }
        if hi > MAX_FREQUENCY_HZ {
            return Err(FreqError::TooHigh {
                value: hi,
                origin: format!("FHI of {}", spec()),
            });
        }
        Ok(LogGrid { lo, hi, n })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Never true: a grid has at least one point.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The first point (Hz).
    pub fn lo_hz(&self) -> f64 {
        self.lo
    }

    /// The last point (Hz).
    pub fn hi_hz(&self) -> f64 {
        self.hi
    }

    /// Point `k` (Hz), `k < len()`.
    pub fn point(&self, k: usize) -> f64 {
        let n = self.n;
        // Endpoints exactly as given (exp(ln x) is not always x).
        if k == 0 {
            self.lo
        } else if k + 1 == n {
            self.hi
        } else {
            let (a, b) = (self.lo.ln(), self.hi.ln());
            (a + (b - a) * k as f64 / (n - 1) as f64).exp()
        }
    }

    /// Points `start .. start + len`, cut at the end of the grid.
    pub fn block(&self, start: usize, len: usize) -> Vec<f64> {
        let end = start.saturating_add(len).min(self.n);
        (start.min(end)..end).map(|k| self.point(k)).collect()
    }
}

/// Checks frequencies given by a caller (an array from Python, say): each finite, >= 0 and at
/// most [`MAX_FREQUENCY_HZ`]. `origin` names them in the message, with the index of the first
/// offending value.
pub fn check_frequencies(freqs_hz: &[f64], origin: &str) -> Result<(), FreqError> {
    match freqs_hz
        .iter()
        .position(|f| !(f.is_finite() && (0.0..=MAX_FREQUENCY_HZ).contains(f)))
    {
        None => Ok(()),
        Some(i) => {
            let (value, origin) = (freqs_hz[i], format!("{origin}, index {i}"));
            Err(match value > MAX_FREQUENCY_HZ {
                true => FreqError::TooHigh { value, origin },
                false => FreqError::Invalid { value, origin },
            })
        }
    }
}

/// Parses `FLO:N:FHI` (Hz, count, Hz), e.g. `1e-4:2000:30`, or a single frequency `F` (Hz);
/// N is at most [`MAX_GRID_POINTS`].
pub fn parse_spec(spec: &str) -> Result<Vec<f64>, FreqError> {
    let grid = parse_log_spec(spec, MAX_GRID_POINTS)?;
    Ok(grid.block(0, grid.len()))
}

/// Parses `FLO:N:FHI` as [`parse_spec`] into a [`LogGrid`] of at most `limit` points (for a
/// grid evaluated block by block, [`crate::limits::MAX_STREAMED_GRID_POINTS`]).
pub fn parse_log_spec(spec: &str, limit: usize) -> Result<LogGrid, FreqError> {
    let origin = || crate::message!("{}", OptionKey::FREQ.given(Shown(spec)));
    let err = |message: &str| FreqError::Spec {
        origin: origin(),
        message: message.into(),
    };
    let parts: Vec<&str> = spec.split(':').map(str::trim).collect();
    let (lo, n_text, hi) = match parts[..] {
        [lo, n_text, hi] => (lo, n_text, hi),
        // One frequency: the grid of one point.
        [f] if f.parse::<f64>().is_ok() => (f, "1", f),
        _ => {
            return Err(err(
                "expected FLO:N:FHI, e.g. 1e-4:2000:30 (Hz:count:Hz), or one frequency F (Hz)",
            ))
        }
    };
    let lo: f64 = lo.parse().map_err(|_| err("FLO is not a number"))?;
    let hi: f64 = hi.parse().map_err(|_| err("FHI is not a number"))?;
    let n: usize = match n_text.parse() {
        Ok(n) => n,
        // More digits than a usize holds: a count over the limit all the same.
        Err(e) if *e.kind() == std::num::IntErrorKind::PosOverflow => usize::MAX,
        Err(_) => return Err(err("N is not a positive whole number")),
    };
    check_count(origin, n as f64, POINTS, limit)?;
    LogGrid::new(lo, hi, n, limit).map_err(|e| match e {
        FreqError::Spec { message, .. } => err(&message),
        other => other,
    })
}

/// Modal loss angles below this are treated as undamped when the grid is built: at the pole of
/// such a mode the equilibrated dynamic stiffness has a reciprocal condition number of about
/// `phi_k` times a factor of the mode's shape (down to 1e-3 for the weakly coupled modes of a
/// partly damped model), which would fall below the solvers' singularity threshold
/// [`crate::tf::SINGULAR_RCOND`]. Such a mode is bracketed like an undamped one instead: its
/// peak (of height ~ 1/phi_k > 5e8) is not sampled, only approached to 3e-7 relative.
pub const NEGLIGIBLE_MODAL_LOSS: f64 = 1e3 * crate::tf::SINGULAR_RCOND;

/// Adds points around every mode of `model` inside `[lo, hi]` of `grid`, then sorts and
/// removes duplicates. Undamped modes are bracketed by relative offsets down to 3e-7 (never on the
/// pole); a mode with modal loss angle `phi_k` of at least [`NEGLIGIBLE_MODAL_LOSS`] gets points
/// across its width `f_k phi_k / 2`, one of them on the peak; a mode with a smaller, negligible
/// loss angle is bracketed as an undamped one.
pub fn refine_around_modes(grid: &[f64], model: &Model) -> Vec<f64> {
    let (lo, hi) = grid
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &f| (a.min(f), b.max(f)));
    let modes = NormalModes::new(model);
    let k_imag = model.stiffness_complex().map(|z| z.im);
    let mut out = grid.to_vec();
    for mode in &modes.modes {
        let f = mode.frequency_hz;
        let loss = (mode.shape.transpose() * k_imag * mode.shape)[(0, 0)] / mode.omega_sq;
        let mut add = |x: f64| {
            let g = f * (1.0 + x);
            if g >= lo && g <= hi {
                out.push(g);
            }
        };
        for x in UNDAMPED_OFFSETS {
            if x > loss {
                add(x);
                add(-x);
            }
        }
        if loss >= NEGLIGIBLE_MODAL_LOSS {
            for w in DAMPED_WIDTHS {
                add(w * loss / 2.0);
                add(-w * loss / 2.0);
            }
        }
    }
    out.sort_by(f64::total_cmp);
    out.dedup();
    out
}

/// The default grid: [`DEFAULT_POINTS`] log-spaced points from 0.1 mHz to 30 Hz, refined
/// around every resonance (at most 40 points more per mode: far within [`MAX_GRID_POINTS`]).
pub fn default_grid(model: &Model) -> Vec<f64> {
    let base = log_grid(DEFAULT_F_LO_HZ, DEFAULT_F_HI_HZ, DEFAULT_POINTS)
        .expect("default grid bounds are valid");
    refine_around_modes(&base, model)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frequencies_above_the_limit_are_refused() {
        assert!(check_frequencies(&[0.0, 1e-3, MAX_FREQUENCY_HZ], "f").is_ok());
        for bad in [-1e-3, f64::NAN, f64::INFINITY, 1.000001e6] {
            let e = check_frequencies(&[1.0, bad], "freq_hz")
                .unwrap_err()
                .to_string();
            let limit = if bad > 0.0 {
                "<= 1e6 Hz"
            } else {
                "finite and >= 0"
            };
            assert!(e.contains("freq_hz, index 1") && e.contains(limit), "{e}");
        }
        let e = log_grid(1e300, 1e301, 2).unwrap_err().to_string();
        assert!(
            e.contains("1e301 Hz (FHI of log grid 1e300:2:1e301)"),
            "{e}"
        );
    }

    #[test]
    fn log_grid_endpoints_and_ratio() {
        let g = log_grid(1e-3, 10.0, 5).unwrap();
        assert_eq!(g.len(), 5);
        assert_eq!((g[0], g[4]), (1e-3, 10.0));
        // Constant ratio 10 between neighbours, to the rounding of exp/ln (a few ulps).
        for w in g.windows(2) {
            assert!((w[1] / w[0] - 10.0).abs() < 1e-13 * 10.0, "{w:?}");
        }
    }

    #[test]
    fn grids_over_the_limit_are_refused_before_allocating() {
        assert_eq!(
            log_grid(1.0, 2.0, MAX_GRID_POINTS).unwrap().len(),
            MAX_GRID_POINTS
        );
        for spec in [
            "1e-3:18446744073709551615:1",
            "1e-4:1000000000:30",
            "1e-4:99999999999999999999999:30",
            "1e-4:1000001:30",
        ] {
            let e = parse_spec(spec).unwrap_err();
            assert!(matches!(e, FreqError::TooLarge(_)), "{spec}: {e}");
            let e = e.to_string();
            assert!(
                e.starts_with(&format!("freq={spec}: "))
                    && e.contains("frequency points")
                    && e.contains("more than the 1000000 allowed"),
                "{e}"
            );
        }
        let e = log_grid(1.0, 2.0, usize::MAX).unwrap_err().to_string();
        assert!(e.contains("more than the 1000000 allowed"), "{e}");
    }

    #[test]
    fn spec_errors_name_the_problem() {
        assert!(parse_spec("1e-3:10")
            .unwrap_err()
            .to_string()
            .contains("FLO:N:FHI"));
        assert!(parse_spec("a:10:1")
            .unwrap_err()
            .to_string()
            .contains("FLO"));
        assert!(parse_spec("1:0:10")
            .unwrap_err()
            .to_string()
            .contains("N >= 1"));
        assert!(parse_spec("-1:10:10")
            .unwrap_err()
            .to_string()
            .contains("0 < FLO"));
        assert!(parse_spec("10:10:1")
            .unwrap_err()
            .to_string()
            .contains("FLO <= FHI"));
        assert!(parse_spec("1e-4:4294967296:30")
            .unwrap_err()
            .to_string()
            .contains("more than the 1000000 allowed"));
    }

    /// A single loss angle leaves the modes that touch its element only weakly with modal loss
    /// angles near 1e-13: the default grid must bracket them as undamped instead of sampling
    /// their unresolvable peaks, so that every method of the full model evaluates it.
    #[test]
    fn partly_damped_models_evaluate_on_the_default_grid() {
        use crate::model::Request;
        use crate::params::Params;
        use crate::tf::{evaluate, plan, Method};
        let keys = [
            "loss.torsion_a_rad",
            "loss.torsion_b_rad",
            "loss.bouncing_a_rad",
            "loss.bouncing_b_rad",
            "loss.bending_a_rad",
            "loss.bending_b_rad",
        ];
        for key in keys {
            let params = Params::table_i()
                .with_override(&format!("{key}=1e-3"))
                .unwrap();
            let model = Model::new(&params).unwrap();
            let grid = default_grid(&model);
            for method in [Method::Direct, Method::Split, Method::PoleZero] {
                let tf = plan(&model, &Request::all_tilt(), method).unwrap();
                if let Err(e) = evaluate(tf.as_ref(), &grid) {
                    panic!("{key}=1e-3, {}: {e}", method.name());
                }
            }
        }
    }
}

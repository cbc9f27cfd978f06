//! Do the resonances present in each simulated channel match the observability table?
//!
//! For every channel (observable) and mode `k` the one-sided ASD of the channel is examined at
//! the bin `k0` of the mode's apparent frequency (aliased into `0 ..= fs/2` when above
//! Nyquist, see [`aliased_frequency_hz`]):
//!
//! * **Peak present**: the largest local maximum within +/- 2 bins of `k0` (the Hann main lobe)
//!   stands above the median of the neighbourhood 8 to 40 bins away by more than
//!   [`PEAK_FACTOR`]. Derivation: on white noise each Welch bin of the PSD is, per segment, an
//!   exponential variable; the mean of `K >= 1` of them exceeds `x` times its expectation with
//!   probability at most `exp(-x)`. The factor 10 on the ASD is 100 on the PSD over the
//!   neighbourhood median, i.e. at least `100 ln 2 = 69` times the mean: `exp(-69) = 1e-30` per
//!   bin, negligible over the `< 1e6` bins examined. Without noise, a Hann-windowed sinusoid
//!   stands above its own leakage 8 or more bins away by more than 1e3 (sidelobes fall as
//!   `1/d^3`), so a true resonance clears 10 with a wide margin.
//! * **Relative amplitude**: the sinusoid's amplitude is estimated from the power in the main
//!   lobe, `A = sqrt(2 df sum_{|j - k0| <= 3} PSD_j)` (+/- 3 bins contain the whole +/- 2-bin
//!   main lobe wherever the tone falls within its bin, so `A` carries no scalloping loss), and
//!   divided by the mode's modal amplitude `|a_k|` of the run's initial state. That estimates
//!   the observable amplitude `|C v_k|` of the mass-normalized shape, the very quantity the
//!   table thresholds. Normalized by the channel's largest estimate it is compared with
//!   [`VISIBILITY_THRESHOLD`] itself: the check's threshold *is* the table's, not a tuned one.
//! * A mode is **seen in the spectrum** when its peak is present and its relative amplitude is
//!   at least [`VISIBILITY_THRESHOLD`]. Within a block, modes the table does not see can show
//!   tiny but genuine peaks (6e-8 .. 2.5e-4 of the channel's largest); they count as not seen,
//!   exactly as in the table.
//! * Not testable: a mode with zero modal amplitude ([`Presence::NotExcited`]); a mode whose
//!   predicted peak at the worst Hann scalloping (`8 / (3 pi) = 0.849`) does not clear
//!   [`PEAK_FACTOR`] times the channel's readout ASD ([`Presence::BelowFloor`]); a mode closer
//!   than 8 bins to another mode the channel responds to ([`Presence::Unresolved`]: increase the
//!   Welch segment).
//!
//! The predicted peak of a sinusoid of amplitude `A` in a periodic-Hann Welch ASD of segment
//! `N` at sampling rate `fs`, tone centred in a bin, is `A sqrt(N / (3 fs))`
//! (`(sum w)^2 / sum w^2 = 2N/3`).

use super::aliased_frequency_hz;
use crate::model::Observable;
use crate::modes::{NormalModes, VISIBILITY_THRESHOLD};
use crate::spectral::Psd;
use std::fmt::Write as _;

/// Peak over neighbourhood median (ASD ratio) for "a peak is present"; derived in the module
/// docs.
pub const PEAK_FACTOR: f64 = 10.0;

/// Half-width (bins) of the window summed for the main-lobe power.
pub const MAIN_LOBE_HALF_WIDTH_BINS: usize = 3;

/// The neighbourhood used as local floor: bins this far from the peak bin (inclusive range).
pub const NEIGHBOURHOOD_BINS: (usize, usize) = (8, 40);

/// Worst-case Hann scalloping (amplitude), tone half a bin off: `8 / (3 pi)`.
pub const HANN_WORST_SCALLOPING: f64 = 8.0 / (3.0 * std::f64::consts::PI);

/// What the spectrum says about one mode in one channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Presence {
    /// A peak with relative amplitude >= [`VISIBILITY_THRESHOLD`].
    Seen,
    /// No peak, or one below [`VISIBILITY_THRESHOLD`] of the channel's largest.
    NotSeen,
    /// The run's initial state does not excite the mode (modal amplitude 0).
    NotExcited,
    /// Any peak would be hidden by the readout noise.
    BelowFloor,
    /// Another mode the channel responds to is closer than 8 bins.
    Unresolved,
}

impl Presence {
    /// Short name for tables.
    pub fn name(self) -> &'static str {
        match self {
            Presence::Seen => "seen",
            Presence::NotSeen => "not seen",
            Presence::NotExcited => "not excited",
            Presence::BelowFloor => "below floor",
            Presence::Unresolved => "unresolved",
        }
    }
}

/// One mode in one channel.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeInChannel {
    /// 1-based mode index (nu_k).
    pub mode_index: usize,
    /// Mode frequency (Hz).
    pub frequency_hz: f64,
    /// Where it appears in the sampled record (Hz), aliased when above Nyquist.
    pub apparent_frequency_hz: f64,
    /// The observability table says the channel sees the mode.
    pub table_seen: bool,
    /// `|C v_k|` over the channel's largest `|C v|`: what the table thresholds.
    pub table_ratio: f64,
    /// Local maximum over the neighbourhood median (0 without a local maximum).
    pub peak_ratio: f64,
    /// Estimated `|C v_k|` from the spectrum over the channel's largest estimate (NaN when
    /// not testable).
    pub spectrum_ratio: f64,
    /// The spectrum's verdict.
    pub spectrum: Presence,
}

impl ModeInChannel {
    /// `Some(true)` when spectrum and table agree, `Some(false)` when they do not, `None` when
    /// the mode is not testable in this run.
    pub fn agrees(&self) -> Option<bool> {
        match self.spectrum {
            Presence::Seen => Some(self.table_seen),
            Presence::NotSeen => Some(!self.table_seen),
            _ => None,
        }
    }
}

/// One channel's modes.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelCheck {
    /// The channel.
    pub observable: Observable,
    /// White readout ASD of the channel (unit/sqrt(Hz)), 0 if noiseless.
    pub readout_asd: f64,
    /// One entry per mode, nu_1 first.
    pub modes: Vec<ModeInChannel>,
}

/// The whole check.
#[derive(Debug, Clone, PartialEq)]
pub struct ResonanceCheck {
    /// Frequency resolution of the ASDs (Hz).
    pub df_hz: f64,
    /// Sampling frequency (Hz).
    pub fs_hz: f64,
    /// Per channel, in [`Observable::ALL`] order of the input.
    pub channels: Vec<ChannelCheck>,
}

impl ResonanceCheck {
    /// True when every testable (channel, mode) agrees with the table.
    pub fn all_agree(&self) -> bool {
        self.disagreements().is_empty()
    }

    /// `(channel, mode index)` pairs where spectrum and table disagree.
    pub fn disagreements(&self) -> Vec<(Observable, usize)> {
        self.channels
            .iter()
            .flat_map(|c| {
                c.modes
                    .iter()
                    .filter(|m| m.agrees() == Some(false))
                    .map(move |m| (c.observable, m.mode_index))
            })
            .collect()
    }

    /// Number of testable (channel, mode) pairs.
    pub fn n_tested(&self) -> usize {
        self.channels
            .iter()
            .flat_map(|c| &c.modes)
            .filter(|m| m.agrees().is_some())
            .count()
    }

    /// A terminal table: one line per channel, one column per mode: `+` seen by both, `.` by
    /// neither, `!` disagreement, `~` not testable.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "resonance check (ASD peaks vs the observability table, threshold {VISIBILITY_THRESHOLD:e} \
             of the channel's largest; df = {:.3e} Hz):",
            self.df_hz
        );
        let _ = write!(s, "  {:<6}", "");
        if let Some(c) = self.channels.first() {
            for m in &c.modes {
                let _ = write!(s, " {:>5}", format!("nu_{}", m.mode_index));
            }
        }
        let _ = writeln!(s, "   (+ seen, . not seen, ! disagrees, ~ not testable)");
        for c in &self.channels {
            let _ = write!(s, "  {:<6}", c.observable.name());
            for m in &c.modes {
                let mark = match (m.agrees(), m.spectrum) {
                    (Some(true), Presence::Seen) => "+",
                    (Some(true), _) => ".",
                    (Some(false), _) => "!",
                    (None, _) => "~",
                };
                let _ = write!(s, " {mark:>5}");
            }
            let _ = writeln!(s);
        }
        for c in &self.channels {
            for m in &c.modes {
                match m.agrees() {
                    Some(false) => {
                        let _ = writeln!(
                            s,
                            "  DISAGREES: {} nu_{}: table {} (ratio {:.1e}), spectrum {} (ratio {:.1e}, peak/floor {:.1e})",
                            c.observable.name(),
                            m.mode_index,
                            if m.table_seen { "seen" } else { "not seen" },
                            m.table_ratio,
                            m.spectrum.name(),
                            m.spectrum_ratio,
                            m.peak_ratio
                        );
                    }
                    None if m.table_seen => {
                        let _ = writeln!(
                            s,
                            "  not testable: {} nu_{} ({})",
                            c.observable.name(),
                            m.mode_index,
                            m.spectrum.name()
                        );
                    }
                    _ => {}
                }
            }
        }
        let _ = writeln!(
            s,
            "  {} of {} testable (channel, mode) pairs agree",
            self.n_tested() - self.disagreements().len(),
            self.n_tested()
        );
        s
    }
}

/// Local maximum within +/- 2 bins of `k0` over the neighbourhood median, and the main-lobe
/// power sum (PSD, unit^2/Hz, summed over +/- [`MAIN_LOBE_HALF_WIDTH_BINS`]).
fn peak_at(psd: &[f64], k0: usize) -> (f64, f64) {
    let n = psd.len();
    let mut best: f64 = 0.0;
    for k in k0.saturating_sub(2).max(1)..=(k0 + 2).min(n.saturating_sub(2)) {
        if psd[k] > 0.0 && psd[k] >= psd[k - 1] && psd[k] >= psd[k + 1] {
            best = best.max(psd[k]);
        }
    }
    let (near, far) = NEIGHBOURHOOD_BINS;
    let mut nb: Vec<f64> = (k0.saturating_sub(far)..k0.saturating_sub(near - 1))
        .chain(k0 + near..(k0 + far + 1).min(n))
        .filter(|&k| k >= 2)
        .map(|k| psd[k])
        .collect();
    nb.sort_by(f64::total_cmp);
    let median = nb.get(nb.len() / 2).copied().unwrap_or(0.0);
    let ratio = if best == 0.0 {
        0.0
    } else if median > 0.0 {
        (best / median).sqrt()
    } else {
        f64::INFINITY
    };
    let lo = k0.saturating_sub(MAIN_LOBE_HALF_WIDTH_BINS).max(1);
    let hi = (k0 + MAIN_LOBE_HALF_WIDTH_BINS).min(n - 1);
    let power: f64 = psd[lo..=hi].iter().sum();
    (ratio, power)
}

/// Runs the check on one-sided Welch PSDs (periodic Hann, segment `segment_len`, sampling
/// frequency `fs_hz`) of the channels, given the modal amplitudes `|a_k|` of the run's initial state (mass-normalized,
/// nu_1 first; e.g. `hypot(u0, v0)` of [`super::ModalPropagator::initial_modal_state`]) and the
/// white readout ASD of each channel (unit/sqrt(Hz); missing means noiseless).
pub fn check_resonances(
    modes: &NormalModes,
    modal_amplitude: &[f64; 8],
    psds: &[(Observable, Psd)],
    fs_hz: f64,
    segment_len: usize,
    readout_asd: &[(Observable, f64)],
) -> ResonanceCheck {
    let df_hz = fs_hz / segment_len as f64;
    let mut channels = Vec::new();
    for (o, psd) in psds {
        let oi = o.index();
        let largest = modes
            .modes
            .iter()
            .map(|m| m.observable_amplitude[oi].abs())
            .fold(0.0, f64::max);
        let readout = readout_asd
            .iter()
            .find(|(x, _)| x == o)
            .map_or(0.0, |r| r.1);
        let apparent: Vec<f64> = modes
            .modes
            .iter()
            .map(|m| aliased_frequency_hz(m.frequency_hz, fs_hz))
            .collect();
        let bins: Vec<usize> = apparent
            .iter()
            .map(|f| (f / df_hz).round() as usize)
            .collect();
        let mut entries = Vec::new();
        let mut estimates = Vec::new();
        for (k, mode) in modes.modes.iter().enumerate() {
            let cv = mode.observable_amplitude[oi].abs();
            let table_ratio = if largest > 0.0 { cv / largest } else { 0.0 };
            let (peak_ratio, power) = peak_at(&psd.psd, bins[k]);
            let a = modal_amplitude[k];
            // Predicted peak at the worst scalloping, from the table's own amplitude.
            let predicted_peak =
                HANN_WORST_SCALLOPING * cv * a * (segment_len as f64 / (3.0 * fs_hz)).sqrt();
            let crowded = modes.modes.iter().enumerate().any(|(j, other)| {
                j != k
                    && other.observable_amplitude[oi] != 0.0
                    && modal_amplitude[j] > 0.0
                    && bins[j].abs_diff(bins[k]) < NEIGHBOURHOOD_BINS.0
            });
            let status = if a == 0.0 {
                Presence::NotExcited
            } else if crowded && cv != 0.0 {
                Presence::Unresolved
            } else if mode_is_seen_by_table(modes, k, *o) && predicted_peak < PEAK_FACTOR * readout
            {
                Presence::BelowFloor
            } else {
                // Decided below, once the channel's largest estimate is known.
                Presence::NotSeen
            };
            let estimate = if status == Presence::NotSeen && peak_ratio > PEAK_FACTOR {
                (2.0 * df_hz * power).sqrt() / a
            } else {
                f64::NAN
            };
            estimates.push(estimate);
            entries.push(ModeInChannel {
                mode_index: mode.index,
                frequency_hz: mode.frequency_hz,
                apparent_frequency_hz: apparent[k],
                table_seen: modes.visible[k][oi],
                table_ratio,
                peak_ratio,
                spectrum_ratio: f64::NAN,
                spectrum: status,
            });
        }
        let max_estimate = estimates
            .iter()
            .copied()
            .filter(|e| e.is_finite())
            .fold(0.0, f64::max);
        for (e, est) in entries.iter_mut().zip(&estimates) {
            if e.spectrum != Presence::NotSeen {
                continue;
            }
            if est.is_finite() && max_estimate > 0.0 {
                e.spectrum_ratio = est / max_estimate;
                if e.spectrum_ratio >= VISIBILITY_THRESHOLD {
                    e.spectrum = Presence::Seen;
                }
            } else {
                e.spectrum_ratio = 0.0;
            }
        }
        channels.push(ChannelCheck {
            observable: *o,
            readout_asd: readout,
            modes: entries,
        });
    }
    ResonanceCheck {
        df_hz,
        fs_hz,
        channels,
    }
}

fn mode_is_seen_by_table(modes: &NormalModes, k: usize, o: Observable) -> bool {
    modes.visible[k][o.index()]
}

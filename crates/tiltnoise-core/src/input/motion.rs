//! The channels of a record as inputs of the model: which input each feeds
//! ([`GroundChannel::input`]), what it measures of it ([`GroundQuantity`]), and what its sensor
//! senses besides ([`Sensing`]); and [`GroundMap`], which carries the channels' cross-spectra
//! (in their own quantities) to those of the model's inputs, bin by bin and exactly.
//!
//! # Quantities
//!
//! A channel of quantity `q` holds `c(f)^-1` times the displacement `u` of its input, with
//! `c = 1`, `1 / (i w)`, `-1 / w^2` for a displacement, a velocity, an acceleration
//! ([`crate::ground`]). So the one-sided CSD of the inputs is `S^u_ij = conj(c_i) c_j S^q_ij`
//! at every bin `f > 0`: the transfer function per unit of each channel's quantity applied to
//! its own spectrum, with nothing integrated in time. At `f = 0` a rate carries no
//! displacement, and the DC bin is dropped for every channel.
//!
//! # Inertial sensors
//!
//! A horizontal seismometer or accelerometer senses tilt as the pendulum does (the equivalence
//! principle of [`crate::model::translation`]: a tilt `eta_t` acts as the floor acceleration
//! `a_x = g eta_t`, `theta_t` as `a_y = -g theta_t`):
//!
//! ```text
//! a_meas,x = a_x + g eta_t,        a_meas,y = a_y - g theta_t.
//! ```
//!
//! With `a = -w^2 u` the displacement it reports is `u_meas,x = x_t - g eta_t / w^2`, so where
//! the record also has the tilt of that axis from a rotation sensor, the translation is
//! recovered as `x_t = u_meas,x + g eta_t / w^2` and `y_t = u_meas,y - g theta_t / w^2`. A
//! pendulum tiltmeter is the same instrument read the other way, `eta_meas = eta_t + a_x / g`,
//! `theta_meas = theta_t - a_y / g`; with a true translation of that axis in the record (a
//! displacement sensor, or a seismometer already corrected), `eta_t = eta_meas + w^2 x_t / g`
//! and `theta_t = theta_meas - w^2 y_t / g`. An inertial
//! tiltmeter and an inertial seismometer of one axis read the same combination and cannot be
//! told apart: such a record is refused. Vertical sensors and `phi_t` sense neither to first
//! order.

use super::rate::angle_psd_divisor;
use super::unit::Motion;
use super::{ground_index, motion_of, Quantity};
use crate::ground::GroundQuantity;
use crate::model::{Input, TiltAxis, TranslationAxis};
use crate::spectral::CrossSpectra;
use num_complex::Complex64;

/// What a channel's sensor senses besides its own motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Sensing {
    /// Its own motion alone: a rotation sensor (ring laser, beam rotation sensor), or a
    /// translation channel from which the tilt is removed already.
    Direct,
    /// Tilt and horizontal acceleration together, as an inertial sensor does: a seismometer or
    /// accelerometer (`a + g t`), or a pendulum tiltmeter (`t + a / g`).
    Inertial,
}

impl Sensing {
    /// What a channel of `motion` is taken to be unless declared otherwise: rotation channels
    /// read rotation alone (rotation sensors); translation channels are inertial sensors
    /// (seismometers, accelerometers).
    pub fn default_for(motion: Motion) -> Sensing {
        match motion {
            Motion::Rotation => Sensing::Direct,
            Motion::Translation => Sensing::Inertial,
        }
    }
}

/// One channel of a record, as an input of the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct GroundChannel {
    /// The input it feeds: a tilt axis or a floor translation.
    pub input: Input,
    /// What it measures of that input.
    pub quantity: GroundQuantity,
    /// What its sensor senses besides.
    pub sensing: Sensing,
}

impl GroundChannel {
    /// A tilt channel of `quantity` read by a rotation sensor.
    pub fn tilt(axis: TiltAxis, quantity: Quantity) -> GroundChannel {
        GroundChannel {
            input: Input::Tilt(axis),
            quantity: match quantity {
                Quantity::Angle => GroundQuantity::Displacement,
                Quantity::Rate => GroundQuantity::Velocity,
            },
            sensing: Sensing::Direct,
        }
    }

    /// The unit of its samples: `rad`, `rad/s`, `m`, `m/s` or `m/s^2`.
    pub fn unit(&self) -> &'static str {
        super::unit::si_unit(motion_of(self.input), self.quantity)
    }
}

/// Which channels' sensors are declared other than [`Sensing::default_for`]: rotation channels
/// read by a pendulum tiltmeter, and translation channels already free of tilt.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Sensors {
    /// Tilt axes read by a pendulum (inertial) tiltmeter: `t + a / g`.
    pub pendulum: Vec<TiltAxis>,
    /// Translation axes whose tilt part is removed already (or read by a sensor that has none).
    pub corrected: Vec<TranslationAxis>,
}

impl Sensors {
    /// The sensing of a channel feeding `input`.
    pub fn sensing(&self, input: Input) -> Sensing {
        match input {
            Input::Tilt(a) if self.pendulum.contains(&a) => Sensing::Inertial,
            Input::Translation(t) if self.corrected.contains(&t) => Sensing::Direct,
            other => Sensing::default_for(motion_of(other)),
        }
    }
}

/// The horizontal axes on which a tilt and a floor acceleration are equivalent, with the sign
/// `s` of `a_meas = a + s g t` (a seismometer) and `t_meas = t + s a / g` (a pendulum
/// tiltmeter): `+1` for `(eta_t, x_t)`, `-1` for `(theta_t, y_t)`.
pub const EQUIVALENT_AXES: [(TiltAxis, TranslationAxis, f64); 2] = [
    (TiltAxis::EtaT, TranslationAxis::XT, 1.0),
    (TiltAxis::ThetaT, TranslationAxis::YT, -1.0),
];

/// A correction of one channel by another, in displacements: `v_target += coefficient(f)
/// v_partner` with `coefficient = sign * (g / w^2)^power`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Correction {
    target: usize,
    partner: usize,
    sign: f64,
    /// `+1`: a translation corrected by a tilt (`g / w^2`); `-1`: a tilt corrected by a
    /// translation (`w^2 / g`).
    power: i32,
}

/// The channels' factors to displacement and the corrections of inertial sensors, for a set of
/// channels: what turns their Welch cross-spectra into those of the model's inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundMap {
    channels: Vec<GroundChannel>,
    corrections: Vec<Correction>,
    g_m_per_s2: f64,
    notes: Vec<String>,
}

/// The exact phase and the power of `w` of a quantity's factor `c = phase / w^power`.
fn factor_parts(q: GroundQuantity) -> (Complex64, i32) {
    match q {
        GroundQuantity::Displacement => (Complex64::new(1.0, 0.0), 0),
        GroundQuantity::Velocity => (Complex64::new(0.0, -1.0), 1),
        GroundQuantity::Acceleration => (Complex64::new(-1.0, 0.0), 2),
    }
}

impl GroundMap {
    /// The map of `channels` (in canonical order, each input once), with the gravity
    /// `g_m_per_s2` of the inertial corrections.
    ///
    /// # Errors
    ///
    /// The name of the input and why, when an inertial tiltmeter and an inertial seismometer
    /// read the same combination of one axis (they cannot be told apart).
    pub fn new(channels: &[GroundChannel], g_m_per_s2: f64) -> Result<GroundMap, String> {
        let (corrections, notes) = plan_corrections(channels)?;
        Ok(GroundMap {
            channels: channels.to_vec(),
            corrections,
            g_m_per_s2,
            notes,
        })
    }

    /// The inputs of the map's spectra, one per channel, in channel order.
    pub fn inputs(&self) -> Vec<Input> {
        self.channels.iter().map(|c| c.input).collect()
    }

    /// The notes on the sensors: the corrections made, inertial sensors left as they are.
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// The names of the channels of `quantity` (of the floor's translation only, with
    /// `translation_only`).
    fn named(&self, quantity: GroundQuantity, translation_only: bool) -> Vec<&'static str> {
        self.channels
            .iter()
            .filter(|c| c.quantity == quantity)
            .filter(|c| !translation_only || motion_of(c.input) == Motion::Translation)
            .map(|c| c.input.name())
            .collect()
    }

    /// The notes of [`GroundMap::apply`] on the translations given as a velocity or an
    /// acceleration (a tilt rate has the budget's own note).
    pub fn spectra_notes(&self) -> Vec<String> {
        [
            (GroundQuantity::Velocity, "a velocity", 2),
            (GroundQuantity::Acceleration, "an acceleration", 4),
        ]
        .into_iter()
        .filter_map(|(quantity, what, power)| {
            let names = self.named(quantity, true);
            (!names.is_empty()).then(|| {
                format!(
                    "{}: the Welch cross-spectra of {what} divided by (2 pi f)^{power} at every \
                     bin f > 0, exact up to Nyquist (no time integration); the DC bin carries no \
                     displacement and is excluded",
                    names.join(", ")
                )
            })
        })
        .collect()
    }

    /// The note of [`GroundMap::displacements`] when it integrates a channel, else `None`.
    pub fn series_note(&self) -> Option<String> {
        let mut names = self.named(GroundQuantity::Velocity, false);
        names.extend(self.named(GroundQuantity::Acceleration, false));
        (!names.is_empty()).then(|| {
            format!(
                "{}: integrated to displacement in the frequency domain (the DFT of the whole \
                 record divided by i 2 pi f per integration on every bin, exact up to Nyquist; \
                 the displacement's mean is unknown and set to 0)",
                names.join(", ")
            )
        })
    }

    /// Whether the map changes nothing: displacements only, no correction.
    pub fn is_identity(&self) -> bool {
        self.corrections.is_empty()
            && self
                .channels
                .iter()
                .all(|c| c.quantity == GroundQuantity::Displacement)
    }

    /// The cross-spectra of the inputs (displacements: rad, m) from Welch cross-spectra of the
    /// channels, on the bins `f > 0`: `(freqs_hz, csd)` with `csd[((k - 1) n + i) n + j]`
    /// (rad^2/Hz, rad m/Hz, m^2/Hz). The DC bin is dropped for every channel.
    pub fn apply(&self, spectra: &CrossSpectra) -> (Vec<f64>, Vec<Complex64>) {
        let nn = spectra.n_channels * spectra.n_channels;
        let mut inputs = spectra.clone();
        self.apply_in_place(&mut inputs);
        (inputs.freqs_hz.split_off(1), inputs.data.split_off(nn))
    }

    /// [`GroundMap::apply`] in place: every bin `f > 0` of `spectra` becomes the inputs'; the
    /// DC bin, which carries no displacement of a rate, is left as it was and must be skipped
    /// (`&spectra.data[n * n..]`, `&spectra.freqs_hz[1..]`).
    pub fn apply_in_place(&self, spectra: &mut CrossSpectra) {
        let n = spectra.n_channels;
        assert_eq!(
            n,
            self.channels.len(),
            "one spectrum per channel of the map"
        );
        if self.is_identity() {
            return;
        }
        let nn = n * n;
        let parts: Vec<(Complex64, i32)> = self
            .channels
            .iter()
            .map(|c| factor_parts(c.quantity))
            .collect();
        let one = Complex64::new(1.0, 0.0);
        let freqs = &spectra.freqs_hz[1..];
        for (block, &f) in spectra.data[nn..].chunks_exact_mut(nn).zip(freqs) {
            let w2 = angle_psd_divisor(Quantity::Rate, f).expect("Welch bins above DC have f > 0");
            let w = crate::units::angular(f);
            // The matrix is Hermitian and stays so: the upper triangle is scaled and the lower
            // one is its conjugate (bitwise what scaling it would give).
            for i in 0..n {
                for j in i..n {
                    let (pi, ki) = parts[i];
                    let (pj, kj) = parts[j];
                    let s = &mut block[i * n + j];
                    let phase = pi.conj() * pj;
                    if phase != one {
                        *s *= phase;
                    }
                    match ki + kj {
                        0 => {}
                        1 => *s /= w,
                        2 => *s /= w2,
                        3 => *s /= w2 * w,
                        _ => *s /= w2 * w2,
                    }
                    if j > i {
                        block[j * n + i] = block[i * n + j].conj();
                    }
                }
            }
            for c in &self.corrections {
                let coefficient = c.sign * (self.g_m_per_s2 / w2).powi(c.power);
                // v_t += a v_p with a real: S_tb += a S_pb, then S_at += a S_ap.
                for b in 0..n {
                    let add = block[c.partner * n + b] * coefficient;
                    block[c.target * n + b] += add;
                }
                for a in 0..n {
                    let add = block[a * n + c.partner] * coefficient;
                    block[a * n + c.target] += add;
                }
            }
            // A corrected channel's PSD is a difference of nearly equal terms where the sensor
            // read mostly the other motion: rounding may leave it at -eps times those terms,
            // which is no power. Clip it (a NaN stays NaN for the finiteness check).
            for c in &self.corrections {
                let s = &mut block[c.target * n + c.target];
                *s = Complex64::new(if s.re < 0.0 { 0.0 } else { s.re }, 0.0);
            }
        }
    }

    /// The weights of the channels' spectra that give, at a bin `f > 0`, the response
    /// `sum_i h[i] U_i` to the inputs' spectra `U` (the displacements [`GroundMap::apply`]
    /// describes): `h` (one transfer function per input, in channel order) becomes, in place,
    /// the `g` of `sum_c g[c] X_c` over the channels' spectra `X`. The inertial corrections are
    /// applied transposed, in reverse order, then each channel's factor to displacement; the
    /// propagation of [`GroundMap::apply`]'s matrix through `h` is then `|sum_c g[c] X_c|^2`,
    /// equal up to rounding.
    pub fn channel_weights(&self, f: f64, h: &mut [Complex64]) {
        assert_eq!(
            h.len(),
            self.channels.len(),
            "one transfer function per channel of the map"
        );
        if self.is_identity() {
            return;
        }
        let w2 = angle_psd_divisor(Quantity::Rate, f).expect("Welch bins above DC have f > 0");
        let w = crate::units::angular(f);
        // u_target += a u_partner turns sum_i h_i u_i into the same sum with h_partner += a
        // h_target: the last correction made is the first undone.
        for c in self.corrections.iter().rev() {
            let coefficient = c.sign * (self.g_m_per_s2 / w2).powi(c.power);
            let add = h[c.target] * coefficient;
            h[c.partner] += add;
        }
        for (g, channel) in h.iter_mut().zip(&self.channels) {
            let (phase, k) = factor_parts(channel.quantity);
            *g *= phase;
            match k {
                0 => {}
                1 => *g /= w,
                _ => *g /= w2,
            }
        }
    }

    /// The channels' series turned into the inputs' displacements (rad, m), one per channel,
    /// each sampled at `sample_rate_hz` and of one length: the same factors and corrections as
    /// [`GroundMap::apply`], applied to the DFT of the whole record (taken as periodic after
    /// removing each channel's mean) on every bin `0 < k < n/2`. DC and an even length's Nyquist
    /// bin are set to 0 (a displacement's constant is unknown from a rate). A map that is the
    /// identity returns the series unchanged.
    pub fn displacements(&self, data: &[Vec<f64>], sample_rate_hz: f64) -> Vec<Vec<f64>> {
        if self.is_identity() {
            return data.to_vec();
        }
        let n = data.first().map_or(0, Vec::len);
        if n < 2 {
            return vec![vec![0.0; n]; data.len()];
        }
        let mut planner = realfft::RealFftPlanner::<f64>::new();
        let forward = planner.plan_fft_forward(n);
        let inverse = planner.plan_fft_inverse(n);
        let mut bins: Vec<Vec<Complex64>> = data
            .iter()
            .map(|x| {
                let mut time = x.clone();
                let mut out = forward.make_output_vec();
                forward
                    .process(&mut time, &mut out)
                    .expect("buffers made by the plan");
                out
            })
            .collect();
        let zero = Complex64::new(0.0, 0.0);
        for k in 0..bins[0].len() {
            if k == 0 || (n % 2 == 0 && k == n / 2) {
                for b in bins.iter_mut() {
                    b[k] = zero;
                }
                continue;
            }
            let f = k as f64 * sample_rate_hz / n as f64;
            let w = crate::units::angular(f);
            for (b, c) in bins.iter_mut().zip(&self.channels) {
                let (phase, power) = factor_parts(c.quantity);
                b[k] *= phase / w.powi(power);
            }
            let w2 = w * w;
            for c in &self.corrections {
                let coefficient = c.sign * (self.g_m_per_s2 / w2).powi(c.power);
                let add = bins[c.partner][k] * coefficient;
                bins[c.target][k] += add;
            }
        }
        bins.into_iter()
            .map(|mut b| {
                let mut time = vec![0.0; n];
                inverse
                    .process(&mut b, &mut time)
                    .expect("buffers made by the plan");
                time.iter_mut().for_each(|v| *v /= n as f64);
                time
            })
            .collect()
    }
}

/// Checks that the sensors of `channels` can be told apart: an inertial tiltmeter and an
/// inertial seismometer of one axis read the same combination. The message names the inputs
/// and what to do.
pub fn check_sensors(channels: &[GroundChannel]) -> Result<(), String> {
    plan_corrections(channels).map(|_| ())
}

/// The corrections of the inertial sensors of `channels` and the notes saying what is done or
/// left ([`GroundMap::new`]).
fn plan_corrections(channels: &[GroundChannel]) -> Result<(Vec<Correction>, Vec<String>), String> {
    let mut corrections = Vec::new();
    let mut notes = Vec::new();
    let find = |input: Input| channels.iter().position(|c| c.input == input);
    for (tilt, translation, sign) in EQUIVALENT_AXES {
        let (t, x) = (Input::Tilt(tilt), Input::Translation(translation));
        let (tn, xn) = (tilt.name(), translation.name());
        match (find(t), find(x)) {
            (Some(ti), Some(xi)) => match (channels[ti].sensing, channels[xi].sensing) {
                (Sensing::Inertial, Sensing::Inertial) => {
                    return Err(format!(
                        "the {tn} channel is a pendulum tiltmeter and the {xn} channel \
                             an inertial seismometer: both read {}, so neither can be \
                             corrected by the other; declare one of them corrected, or \
                             leave one out",
                        reading(tilt, translation, sign)
                    ))
                }
                (Sensing::Direct, Sensing::Inertial) => {
                    corrections.push(Correction {
                        target: xi,
                        partner: ti,
                        sign,
                        power: 1,
                    });
                    notes.push(format!(
                        "the {xn} channel is an inertial sensor, which reads {}: the \
                             tilt it saw is removed with the {tn} channel, {xn} = \
                             {xn},meas {} g {tn} / (2 pi f)^2 bin by bin (declare the \
                             channel corrected if it is already)",
                        reading(tilt, translation, sign),
                        if sign > 0.0 { "+" } else { "-" },
                    ));
                }
                (Sensing::Inertial, Sensing::Direct) => {
                    corrections.push(Correction {
                        target: ti,
                        partner: xi,
                        sign,
                        power: -1,
                    });
                    notes.push(format!(
                        "the {tn} channel is a pendulum tiltmeter, which reads {} + \
                             {}a/g: the acceleration it saw is removed with the {xn} \
                             channel, {tn} = {tn},meas {} (2 pi f)^2 {xn} / g bin by bin",
                        tn,
                        if sign > 0.0 { "" } else { "-" },
                        if sign > 0.0 { "+" } else { "-" },
                    ));
                }
                (Sensing::Direct, Sensing::Direct) => {}
            },
            (None, Some(xi)) if channels[xi].sensing == Sensing::Inertial => {
                notes.push(format!(
                    "the {xn} channel is an inertial sensor and the record has no {tn} \
                     channel: its translation term includes the tilt the seismometer saw \
                     ({}), so a separate {tn} input (another record, a user term) would \
                     count that tilt twice",
                    reading(tilt, translation, sign)
                ));
            }
            (Some(ti), None) if channels[ti].sensing == Sensing::Inertial => {
                notes.push(format!(
                    "the {tn} channel is a pendulum tiltmeter and the record has no {xn} \
                     channel: its tilt term includes the floor acceleration the tiltmeter \
                     saw, so a separate {xn} input would count that acceleration twice"
                ));
            }
            _ => {}
        }
    }
    Ok((corrections, notes))
}

/// What an inertial sensor of `translation` reads: `a_x + g eta_t` or `a_y - g theta_t`.
fn reading(tilt: TiltAxis, translation: TranslationAxis, sign: f64) -> String {
    let a = ["a_x", "a_y", "a_z"][translation.index()];
    format!(
        "{a} {} g {}",
        if sign > 0.0 { "+" } else { "-" },
        tilt.name()
    )
}

/// Sorts channels into canonical input order ([`ground_index`]).
pub fn canonical_order(channels: &mut [GroundChannel]) {
    channels.sort_by_key(|c| ground_index(c.input));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(input: Input, quantity: GroundQuantity, sensing: Sensing) -> GroundChannel {
        GroundChannel {
            input,
            quantity,
            sensing,
        }
    }

    /// One bin's spectra of a known motion: the inputs' displacement amplitudes `u`, the
    /// channels' readings `q` (what each sensor reports, in its own quantity), and the map must
    /// give back `conj(u_i) u_j` within rounding.
    fn check(channels: &[GroundChannel], u: &[Complex64], q: &[Complex64], f: f64, g: f64) {
        let n = channels.len();
        let spectra = CrossSpectra {
            freqs_hz: vec![0.0, f],
            n_channels: n,
            data: (0..2 * n * n)
                .map(|e| {
                    let (i, j) = ((e % (n * n)) / n, e % n);
                    q[i].conj() * q[j]
                })
                .collect(),
            n_segments: 1,
        };
        let map = GroundMap::new(channels, g).unwrap();
        let (freqs, csd) = map.apply(&spectra);
        assert_eq!(freqs, vec![f]);
        // The correction subtracts what the sensor read from the displacement it reported, so
        // the rounding is relative to the larger of the two: the scale sums both.
        let w = crate::units::angular(f);
        let reported = q.iter().zip(channels).map(|(q, c)| {
            let (phase, power) = factor_parts(c.quantity);
            (q * phase / w.powi(power)).norm_sqr()
        });
        let scale: f64 = u.iter().map(|z| z.norm_sqr()).sum::<f64>() + reported.sum::<f64>();
        for i in 0..n {
            for j in 0..n {
                let want = u[i].conj() * u[j];
                let got = csd[i * n + j];
                // A few roundings per factor, relative to the largest product.
                assert!(
                    (got - want).norm() <= 64.0 * f64::EPSILON * scale,
                    "S({i}, {j}) at {f} Hz: {got} vs {want}"
                );
            }
        }
        // The series path: a sinusoid on a DFT bin gives the same amplitudes.
        let (len, fs) = (64usize, 64.0 * f / 5.0);
        let series: Vec<Vec<f64>> = q
            .iter()
            .map(|z| {
                (0..len)
                    .map(|t| {
                        (z * Complex64::from_polar(
                            1.0,
                            std::f64::consts::TAU * 5.0 * t as f64 / len as f64,
                        ))
                        .re
                    })
                    .collect()
            })
            .collect();
        let out = map.displacements(&series, fs);
        for (i, x) in out.iter().enumerate() {
            for (t, v) in x.iter().enumerate() {
                let want = (u[i]
                    * Complex64::from_polar(
                        1.0,
                        std::f64::consts::TAU * 5.0 * t as f64 / len as f64,
                    ))
                .re;
                assert!(
                    (v - want).abs() <= 1e3 * f64::EPSILON * scale.sqrt(),
                    "channel {i}, sample {t}: {v} vs {want}"
                );
            }
        }
    }

    /// A rotation-rate sensor and an accelerometer on the x axis: the accelerometer reads
    /// `a_x + g eta_t`, and the map recovers the floor's displacement x_t and tilt eta_t.
    #[test]
    fn a_seismometer_is_corrected_by_the_rotation_sensor() {
        let (f, g) = (0.02, 9.81);
        let w = crate::units::angular(f);
        let eta = Complex64::from_polar(2e-9, 0.4);
        let x = Complex64::from_polar(3e-7, -1.1);
        let a_x = -w * w * x;
        let channels = [
            channel(
                Input::Tilt(TiltAxis::EtaT),
                GroundQuantity::Velocity,
                Sensing::Direct,
            ),
            channel(
                Input::Translation(TranslationAxis::XT),
                GroundQuantity::Acceleration,
                Sensing::Inertial,
            ),
        ];
        let q = [Complex64::new(0.0, w) * eta, a_x + g * eta];
        check(&channels, &[eta, x], &q, f, g);
    }

    /// The y axis has the other sign: `a_meas,y = a_y - g theta_t`; a pendulum tiltmeter reads
    /// `theta_t - a_y / g` and is corrected by a true displacement sensor.
    #[test]
    fn the_y_axis_and_a_pendulum_tiltmeter() {
        let (f, g) = (0.005, 9.80665);
        let w = crate::units::angular(f);
        let theta = Complex64::from_polar(5e-9, 2.0);
        let y = Complex64::from_polar(1e-6, 0.3);
        let a_y = -w * w * y;
        let seismometer = [
            channel(
                Input::Tilt(TiltAxis::ThetaT),
                GroundQuantity::Displacement,
                Sensing::Direct,
            ),
            channel(
                Input::Translation(TranslationAxis::YT),
                GroundQuantity::Velocity,
                Sensing::Inertial,
            ),
        ];
        // A velocity sensor reports the integral of what it senses: (a_y - g theta) / (i w).
        let q = [theta, (a_y - g * theta) / Complex64::new(0.0, w)];
        check(&seismometer, &[theta, y], &q, f, g);
        let tiltmeter = [
            channel(
                Input::Tilt(TiltAxis::ThetaT),
                GroundQuantity::Displacement,
                Sensing::Inertial,
            ),
            channel(
                Input::Translation(TranslationAxis::YT),
                GroundQuantity::Displacement,
                Sensing::Direct,
            ),
        ];
        check(&tiltmeter, &[theta, y], &[theta - a_y / g, y], f, g);
    }

    #[test]
    fn two_inertial_sensors_of_one_axis_are_refused_and_lone_ones_noted() {
        let eta = channel(
            Input::Tilt(TiltAxis::EtaT),
            GroundQuantity::Displacement,
            Sensing::Inertial,
        );
        let x = channel(
            Input::Translation(TranslationAxis::XT),
            GroundQuantity::Acceleration,
            Sensing::Inertial,
        );
        let e = GroundMap::new(&[eta, x], 9.81).unwrap_err();
        assert!(e.contains("both read a_x + g eta_t"), "{e}");
        let alone = GroundMap::new(&[x], 9.81).unwrap();
        assert!(
            alone.notes()[0].contains("would count that tilt twice"),
            "{:?}",
            alone.notes()
        );
        // Rotation channels alone, as angles: nothing to do, and the spectra pass unchanged.
        let theta = GroundChannel::tilt(TiltAxis::ThetaT, Quantity::Angle);
        assert!(GroundMap::new(&[theta], 9.81).unwrap().is_identity());
    }
}

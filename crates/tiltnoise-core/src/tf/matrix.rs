//! Transfer functions on a frequency grid: [`TransferMatrix`], and the [`Layout`] of its values.
//!
//! Values are stored in planes: one `f64` array over the grid per stored part (the real or the
//! imaginary part of an entry), so each entry's frequency series is contiguous.
//!
//! A plan knows which entries of its matrix are structurally zero (an observable that no block
//! reaching the input moves, e.g. X from theta_t) and, for the pole-zero method on an
//! undamped model, that every entry is real (real poles, zeros and gains). It stores only what
//! can be nonzero: one plane per possibly-nonzero entry and part, two per entry (re, im) or one
//! (real layouts). The 7x3 tilt matrix of Table I has 11 such entries of 21: 11 planes, 88
//! bytes per frequency, instead of the 336 of a dense complex matrix. [`TransferMatrix::get`]
//! returns exact zeros for the others (and `im = 0.0` in a real layout): the values are those
//! of the dense matrix, bit for bit; only the storage differs. Methods without that knowledge
//! (direct, block, split, modal, torsion2) use the dense layout, two planes per entry.

use super::{Input, LowFrequency, Method};
use crate::error::TfError;
use crate::ground::GroundQuantity;
use crate::model::Observable;
use num_complex::Complex64;

/// Which planes hold each entry of an `outputs x inputs` matrix.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Layout {
    /// Per entry (`o * n_inputs + i`): its slot, or `None` for a structural zero.
    slots: Vec<Option<usize>>,
    /// Number of slots.
    n_slots: usize,
    /// One plane per slot (the real part; the imaginary part is exactly 0) instead of two.
    real: bool,
}

impl Layout {
    /// Every one of `n_entries` entries complex, in entry order (`[output][input]` row-major):
    /// planes `2 e` and `2 e + 1` hold entry `e`'s real and imaginary parts.
    pub fn dense(n_entries: usize) -> Layout {
        Layout {
            slots: (0..n_entries).map(Some).collect(),
            n_slots: n_entries,
            real: false,
        }
    }

    /// Slots for the entries with `nonzero[entry]`, in entry order; the others structural
    /// zeros. `real`: one plane per slot.
    pub fn compact(nonzero: &[bool], real: bool) -> Layout {
        let mut n_slots = 0;
        let slots = nonzero
            .iter()
            .map(|&nz| {
                nz.then(|| {
                    n_slots += 1;
                    n_slots - 1
                })
            })
            .collect();
        Layout {
            slots,
            n_slots,
            real,
        }
    }

    /// Number of entries (`outputs x inputs`).
    pub fn n_entries(&self) -> usize {
        self.slots.len()
    }

    /// Number of stored (possibly nonzero) entries.
    pub fn n_stored(&self) -> usize {
        self.n_slots
    }

    /// Every stored entry is real (imaginary parts exactly 0, not stored).
    pub fn is_real(&self) -> bool {
        self.real
    }

    /// Entry `entry` is exactly zero at every frequency (not stored).
    pub fn is_structural_zero(&self, entry: usize) -> bool {
        self.slots[entry].is_none()
    }

    /// Number of planes (`f64` values per frequency).
    pub fn n_planes(&self) -> usize {
        if self.real {
            self.n_slots
        } else {
            2 * self.n_slots
        }
    }

    /// Planes of entry `entry`'s real and imaginary parts (`None` where not stored: a
    /// structural zero, or the imaginary part in a real layout).
    pub fn position(&self, entry: usize) -> (Option<usize>, Option<usize>) {
        match (self.slots[entry], self.real) {
            (None, _) => (None, None),
            (Some(s), true) => (Some(s), None),
            (Some(s), false) => (Some(2 * s), Some(2 * s + 1)),
        }
    }

    /// Whether this is [`Layout::dense`].
    pub fn is_dense(&self) -> bool {
        !self.real && self.n_slots == self.slots.len()
    }
}

/// Transfer functions on a frequency grid: `H_{o,i}(f_k)`, stored in a [`Layout`] (see the
/// module docs); read with [`TransferMatrix::get`] or [`TransferMatrix::dense_values`].
#[derive(Debug, Clone, PartialEq)]
pub struct TransferMatrix {
    /// Frequencies (Hz).
    pub freqs_hz: Vec<f64>,
    /// Row labels.
    pub outputs: Vec<Observable>,
    /// Column labels.
    pub inputs: Vec<Input>,
    /// The method that produced the values.
    pub method: Method,
    /// What the floor's motion (tilt and translation columns) is per unit of: displacement
    /// unless converted by [`TransferMatrix::per_ground_quantity`].
    ground_quantity: GroundQuantity,
    layout: Layout,
    /// `layout.n_planes()` planes of `n_stored_freqs()` values, one after the other.
    data: Vec<f64>,
}

impl TransferMatrix {
    /// A matrix from dense complex values, `[freq][output][input]` row-major.
    ///
    /// # Panics
    ///
    /// If `values` does not hold `freqs_hz.len() x outputs.len() x inputs.len()` values.
    pub fn from_dense(
        freqs_hz: Vec<f64>,
        outputs: Vec<Observable>,
        inputs: Vec<Input>,
        method: Method,
        values: &[Complex64],
    ) -> TransferMatrix {
        let n = outputs.len() * inputs.len();
        assert_eq!(
            values.len(),
            freqs_hz.len() * n,
            "{} values for {} frequencies x {n} entries",
            values.len(),
            freqs_hz.len()
        );
        let nf = freqs_hz.len();
        let mut data = vec![0.0; 2 * n * nf];
        if n > 0 {
            for (k, point) in values.chunks_exact(n).enumerate() {
                for (e, z) in point.iter().enumerate() {
                    data[2 * e * nf + k] = z.re;
                    data[(2 * e + 1) * nf + k] = z.im;
                }
            }
        }
        TransferMatrix {
            freqs_hz,
            outputs,
            inputs,
            method,
            ground_quantity: GroundQuantity::Displacement,
            layout: Layout::dense(n),
            data,
        }
    }

    /// A matrix of `layout` whose `data` (`layout.n_planes()` planes) the caller fills.
    pub(super) fn from_parts(
        freqs_hz: Vec<f64>,
        outputs: Vec<Observable>,
        inputs: Vec<Input>,
        method: Method,
        layout: Layout,
        data: Vec<f64>,
    ) -> TransferMatrix {
        debug_assert_eq!(layout.n_entries(), outputs.len() * inputs.len());
        TransferMatrix {
            freqs_hz,
            outputs,
            inputs,
            method,
            ground_quantity: GroundQuantity::Displacement,
            layout,
            data,
        }
    }

    /// The storage, for [`super::evaluate_into`] to refill in place.
    pub(super) fn parts_mut(&mut self) -> (&mut Layout, &mut Vec<f64>) {
        (&mut self.layout, &mut self.data)
    }

    /// `H_{o,i}(f_k)`, in [`TransferMatrix::unit`] (output unit per input unit), for
    /// `e^{+i w t}` time dependence.
    pub fn get(&self, k: usize, o: usize, i: usize) -> Complex64 {
        let entry = o * self.inputs.len() + i;
        let n = self.n_stored_freqs();
        assert!(k < n, "frequency index {k} of {n}");
        match self.layout.position(entry) {
            (None, _) => Complex64::new(0.0, 0.0),
            (Some(re), None) => Complex64::new(self.data[re * n + k], 0.0),
            (Some(re), Some(im)) => Complex64::new(self.data[re * n + k], self.data[im * n + k]),
        }
    }

    /// The stored values of entry (o, i) over the grid, `(re, im)` (`None` where not stored:
    /// a structural zero, or the imaginary part in a real layout, exactly 0). Units as
    /// [`TransferMatrix::get`]: [`TransferMatrix::unit`].
    pub fn planes(&self, o: usize, i: usize) -> (Option<&[f64]>, Option<&[f64]>) {
        let n = self.n_stored_freqs();
        let plane = |p: Option<usize>| p.map(|p| &self.data[p * n..(p + 1) * n]);
        let (re, im) = self.layout.position(o * self.inputs.len() + i);
        (plane(re), plane(im))
    }

    /// How the values are stored.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// Number of frequencies the stored values cover (`freqs_hz.len()` unless the matrix was
    /// modified inconsistently).
    pub fn n_stored_freqs(&self) -> usize {
        match self.layout.n_planes() {
            0 => self.freqs_hz.len(),
            planes => self.data.len() / planes,
        }
    }

    /// Every value, dense: `[freq][output][input]` row-major complex, over the stored
    /// frequencies ([`TransferMatrix::n_stored_freqs`]).
    pub fn dense_values(&self) -> Vec<Complex64> {
        let (no, ni) = (self.outputs.len(), self.inputs.len());
        let mut out = Vec::with_capacity(self.n_stored_freqs() * no * ni);
        for k in 0..self.n_stored_freqs() {
            for o in 0..no {
                for i in 0..ni {
                    out.push(self.get(k, o, i));
                }
            }
        }
        out
    }

    /// Unit of entry (o, i): output unit per input unit ([`TransferMatrix::input_unit`]).
    pub fn unit(&self, o: usize, i: usize) -> String {
        let input = self.input_unit(i);
        if input.contains(' ') || input.contains('/') {
            format!("{}/({input})", self.outputs[o].unit())
        } else {
            format!("{}/{input}", self.outputs[o].unit())
        }
    }

    /// Unit of input `i` as the values are per: the input's own (rad, m, N, N m), or for the
    /// floor's motion that of [`TransferMatrix::ground_quantity`] (rad/s^2, m/s, ...).
    pub fn input_unit(&self, i: usize) -> String {
        let input = self.inputs[i];
        match input.is_ground() {
            true => self.ground_quantity.unit(input.unit()),
            false => input.unit().to_string(),
        }
    }

    /// What the floor's motion (the tilt and translation columns) is per unit of.
    pub fn ground_quantity(&self) -> GroundQuantity {
        self.ground_quantity
    }

    /// The same transfer functions with the floor's motion (the tilt and translation columns)
    /// per unit `quantity` instead of per unit displacement: each such value times
    /// [`GroundQuantity::to_displacement`] at its frequency (per unit floor acceleration
    /// `H / (-w^2)`), and below [`LowFrequency::exact_below_hz`] the exact low-frequency form's
    /// value, which stays within the range of `f64` where the plan's values and the factor
    /// do not ([`crate::tf::LowFrequency`]); force and torque columns unchanged. Dense layout.
    ///
    /// # Errors
    ///
    /// [`TfError::NoGroundFactor`] at the first frequency where the factor does not exist
    /// (0 Hz for velocity and acceleration) when the matrix has a tilt or translation column;
    /// [`TfError::Overflow`] at the first frequency where an entry's value is beyond the range
    /// of `f64`, naming the entry, the quantity and the frequency.
    ///
    /// # Panics
    ///
    /// If the matrix is not per unit displacement (converted already), or `low` was built for
    /// another request.
    pub fn per_ground_quantity(
        &self,
        quantity: GroundQuantity,
        low: &LowFrequency,
    ) -> Result<TransferMatrix, TfError> {
        assert_eq!(
            self.ground_quantity,
            GroundQuantity::Displacement,
            "converts transfer functions per unit displacement"
        );
        assert!(
            low.request().outputs == self.outputs && low.request().inputs == self.inputs,
            "the low-frequency form of this matrix's request"
        );
        let (no, ni) = (self.outputs.len(), self.inputs.len());
        let mut values = self.dense_values();
        if no > 0 && self.inputs.iter().any(|i| i.is_ground()) {
            for (k, point) in values.chunks_exact_mut(no * ni).enumerate() {
                low.convert(quantity, self.freqs_hz[k], point)?;
            }
        }
        let mut m = TransferMatrix::from_dense(
            self.freqs_hz[..self.n_stored_freqs()].to_vec(),
            self.outputs.clone(),
            self.inputs.clone(),
            self.method,
            &values,
        );
        m.ground_quantity = quantity;
        Ok(m)
    }

    /// Position of an observable among the rows.
    pub fn output_index(&self, o: Observable) -> Option<usize> {
        self.outputs.iter().position(|&x| x == o)
    }

    /// Position of an input among the columns.
    pub fn input_index(&self, i: Input) -> Option<usize> {
        self.inputs.iter().position(|&x| x == i)
    }

    /// The same matrix restricted to the rows `rows` (indices into `outputs`, in that order),
    /// dense.
    pub fn select_outputs(&self, rows: &[usize]) -> TransferMatrix {
        let ni = self.inputs.len();
        let mut values = Vec::with_capacity(self.n_stored_freqs() * rows.len() * ni);
        for k in 0..self.n_stored_freqs() {
            for &o in rows {
                for i in 0..ni {
                    values.push(self.get(k, o, i));
                }
            }
        }
        TransferMatrix::from_dense(
            self.freqs_hz[..self.n_stored_freqs()].to_vec(),
            rows.iter().map(|&o| self.outputs[o]).collect(),
            self.inputs.clone(),
            self.method,
            &values,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::TiltAxis;

    #[test]
    fn compact_layouts_read_back_as_dense() {
        let outputs = vec![Observable::X, Observable::Phi];
        let inputs = vec![Input::Tilt(TiltAxis::ThetaT), Input::Tilt(TiltAxis::EtaT)];
        // Entries (X, theta_t) and (phi, eta_t) stored; real and complex.
        let nonzero = [false, true, false, true];
        for real in [true, false] {
            let layout = Layout::compact(&nonzero, real);
            assert_eq!(layout.n_stored(), 2);
            assert_eq!(layout.n_planes(), if real { 2 } else { 4 });
            let data: Vec<f64> = (0..2 * layout.n_planes()).map(|k| k as f64 + 1.0).collect();
            let m = TransferMatrix::from_parts(
                vec![1.0, 2.0],
                outputs.clone(),
                inputs.clone(),
                Method::PoleZero,
                layout,
                data,
            );
            let dense = m.dense_values();
            assert_eq!(dense.len(), 8);
            for k in 0..2 {
                for e in 0..4 {
                    let z = dense[k * 4 + e];
                    assert_eq!(z, m.get(k, e / 2, e % 2));
                    if !nonzero[e] {
                        assert_eq!((z.re.to_bits(), z.im.to_bits()), (0, 0));
                    } else if real {
                        assert_eq!(z.im.to_bits(), 0);
                    }
                }
            }
            // Slot 1 is entry (phi, eta_t): plane 1 (real) or 2 (complex), point 1.
            let want = if real { 4.0 } else { 6.0 };
            assert_eq!(m.get(1, 1, 1).re, want);
            assert_eq!(m.planes(1, 1).0.unwrap(), [want - 1.0, want]);
            assert_eq!(m.planes(1, 1).1.is_none(), real);
            assert_eq!(m.planes(0, 0), (None, None));
            let rows = m.select_outputs(&[1]);
            assert!(rows.layout().is_dense());
            assert_eq!(rows.get(1, 0, 1), m.get(1, 1, 1));
            assert_eq!(rows.get(0, 0, 0), Complex64::new(0.0, 0.0));
        }
    }

    /// Per unit floor acceleration the ground columns are divided by `-w^2`, the force columns
    /// are untouched, and the units say so; at 0 Hz there is no such value.
    #[test]
    fn ground_columns_per_unit_acceleration() {
        use crate::model::{ForceInput, TranslationAxis};
        let inputs = vec![
            Input::Translation(TranslationAxis::XT),
            Input::Force(ForceInput::ALL[0]),
        ];
        let values = [Complex64::new(2.0, 1.0), Complex64::new(3.0, -1.0)];
        let m = TransferMatrix::from_dense(
            vec![0.5],
            vec![Observable::X],
            inputs.clone(),
            Method::Direct,
            &values,
        );
        let model = crate::model::Model::new(&crate::params::Params::table_i()).unwrap();
        let low = LowFrequency::new(
            &model,
            &crate::model::Request {
                outputs: vec![Observable::X],
                inputs: inputs.clone(),
            },
        );
        let a = m
            .per_ground_quantity(GroundQuantity::Acceleration, &low)
            .unwrap();
        let w2 = crate::units::angular(0.5).powi(2);
        assert_eq!(a.get(0, 0, 0), values[0] * (-1.0 / w2));
        assert_eq!(a.get(0, 0, 1), values[1]);
        assert_eq!(
            (a.unit(0, 0), a.unit(0, 1)),
            ("m/(m/s^2)".into(), "m/N".into())
        );
        assert_eq!(m.unit(0, 0), "m/m");
        let at_dc = TransferMatrix::from_dense(
            vec![0.0],
            vec![Observable::X],
            inputs,
            Method::Direct,
            &values,
        );
        assert!(matches!(
            at_dc.per_ground_quantity(GroundQuantity::Velocity, &low),
            Err(TfError::NoGroundFactor { .. })
        ));
    }

    #[test]
    fn dense_round_trip() {
        let values: Vec<Complex64> = (0..6)
            .map(|k| Complex64::new(k as f64, -(k as f64)))
            .collect();
        let m = TransferMatrix::from_dense(
            vec![0.5, 1.5],
            vec![Observable::X],
            Input::all_tilts(),
            Method::Direct,
            &values,
        );
        assert!(m.layout().is_dense());
        assert_eq!(m.dense_values(), values);
        assert_eq!(m.get(1, 0, 2), values[5]);
    }
}

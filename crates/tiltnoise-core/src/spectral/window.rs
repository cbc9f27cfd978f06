//! Window functions.

use std::f64::consts::PI;

/// Periodic ("DFT-even") Hann window of `n` samples, `w[k] = 1/2 - 1/2 cos(2πk/n)`, as
/// `scipy.signal.get_window('hann', n)` (i.e. `scipy.signal.windows.hann(n, sym=False)`).
///
/// The arithmetic follows scipy's `general_cosine` on `n + 1` points truncated to `n`
/// (`w = 0.5 + 0.5 cos(-π + 2πk/n)`), so the values agree with scipy to the last bit or two.
/// `n = 0` gives an empty window and `n = 1` gives `[1.0]`, as in scipy.
pub fn hann_periodic(n: usize) -> Vec<f64> {
    if n <= 1 {
        return vec![1.0; n];
    }
    // np.linspace(-pi, pi, n + 1): step = (pi - (-pi)) / n, value = k * step + (-pi).
    let step = (PI - (-PI)) / n as f64;
    (0..n)
        .map(|k| {
            let fac = k as f64 * step + (-PI);
            // w = zeros; w += 0.5 * cos(0 * fac); w += 0.5 * cos(1 * fac)
            0.5 + 0.5 * fac.cos()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_of_periodic_hann() {
        for n in [2usize, 7, 8, 64, 127] {
            let w = hann_periodic(n);
            assert_eq!(w.len(), n);
            assert!(w[0].abs() < 1e-15, "w[0] = {}", w[0]);
            for k in 1..n {
                // Periodic: symmetric about n/2 with w[k] = w[n-k].
                assert!((w[k] - w[n - k]).abs() < 1e-15, "n = {n}, k = {k}");
                let exact = 0.5 - 0.5 * (2.0 * PI * k as f64 / n as f64).cos();
                assert!((w[k] - exact).abs() < 1e-15);
            }
            if n % 2 == 0 {
                assert!((w[n / 2] - 1.0).abs() < 1e-15);
            }
        }
        assert!(hann_periodic(0).is_empty());
        assert_eq!(hann_periodic(1), vec![1.0]);
    }

    #[test]
    fn sum_of_squares_is_three_eighths_n() {
        // sum(w^2) = 3n/8 for the periodic Hann window with n >= 3.
        for n in [3usize, 8, 100, 1001] {
            let s: f64 = hann_periodic(n).iter().map(|w| w * w).sum();
            assert!(
                (s - 0.375 * n as f64).abs() < 1e-12 * n as f64,
                "n = {n}: {s}"
            );
        }
    }
}

//! Small numerical kernels that reproduce numpy's arithmetic: pairwise summation, median and
//! scipy's median bias.

/// numpy's pairwise summation (`np.add.reduce` on contiguous float64), reproduced operation by
/// operation: below 8 values a plain loop, up to 128 values eight interleaved partial sums,
/// above that a recursive split at a multiple of 8. Rounding error grows like `O(eps log n)`.
pub(crate) fn pairwise_sum(a: &[f64]) -> f64 {
    const BLOCK: usize = 128;
    let n = a.len();
    if n < 8 {
        let mut res = 0.0;
        for &v in a {
            res += v;
        }
        res
    } else if n <= BLOCK {
        let mut r = [0.0f64; 8];
        r.copy_from_slice(&a[..8]);
        let full = n - n % 8;
        let mut i = 8;
        while i < full {
            for (j, rj) in r.iter_mut().enumerate() {
                *rj += a[i + j];
            }
            i += 8;
        }
        let mut res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        for &v in &a[full..] {
            res += v;
        }
        res
    } else {
        let mut n2 = n / 2;
        n2 -= n2 % 8;
        pairwise_sum(&a[..n2]) + pairwise_sum(&a[n2..])
    }
}

/// Median as `np.median`: the middle value, or the mean of the two middle values for an even
/// count; NaN if any value is NaN or the slice is empty. Reorders `v`.
pub(crate) fn median_in_place(v: &mut [f64]) -> f64 {
    let n = v.len();
    if n == 0 || v.iter().any(|x| x.is_nan()) {
        return f64::NAN;
    }
    let mid = n / 2;
    let (lower, &mut hi, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    if n % 2 == 1 {
        hi
    } else {
        let lo = lower.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo + hi) / 2.0
    }
}

/// scipy's `_median_bias(n)`: ratio of the expected median to the expected mean of `n`
/// exponentially distributed periodogram values,
/// `1 + sum_{i=1}^{(n-1)/2} (1/(2i+1) - 1/(2i))` (tends to `ln 2`).
pub(crate) fn median_bias(n: usize) -> f64 {
    let m = n.saturating_sub(1) / 2;
    let terms: Vec<f64> = (1..=m)
        .map(|i| {
            let ii2 = 2.0 * i as f64;
            1.0 / (ii2 + 1.0) - 1.0 / ii2
        })
        .collect();
    1.0 + pairwise_sum(&terms)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairwise_sum_is_a_sum() {
        for n in [0usize, 1, 5, 8, 9, 127, 128, 129, 1000, 4099] {
            let a: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() + 2.0).collect();
            let naive: f64 = a.iter().sum();
            let pw = pairwise_sum(&a);
            assert!(
                (pw - naive).abs() <= 1e-12 * naive.abs().max(1.0),
                "n = {n}"
            );
        }
        // Exact for integers.
        let a: Vec<f64> = (1..=1000).map(|i| i as f64).collect();
        assert_eq!(pairwise_sum(&a), 500_500.0);
    }

    #[test]
    fn median_odd_even_nan() {
        assert_eq!(median_in_place(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median_in_place(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median_in_place(&mut [-1.0, 5.0]), 2.0);
        assert_eq!(median_in_place(&mut [7.0]), 7.0);
        assert!(median_in_place(&mut [1.0, f64::NAN, 2.0]).is_nan());
        assert!(median_in_place(&mut []).is_nan());
    }

    #[test]
    fn median_bias_values() {
        assert_eq!(median_bias(1), 1.0);
        assert_eq!(median_bias(2), 1.0);
        assert!((median_bias(3) - (1.0 + 1.0 / 3.0 - 0.5)).abs() < 1e-15);
        assert!((median_bias(5) - (1.0 + 1.0 / 3.0 - 0.5 + 0.2 - 0.25)).abs() < 1e-15);
        assert!((median_bias(1_000_001) - std::f64::consts::LN_2).abs() < 1e-6);
    }
}

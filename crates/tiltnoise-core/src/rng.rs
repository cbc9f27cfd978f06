//! The crate's one random-number generator: xoshiro256** seeded by SplitMix64, with
//! Box-Muller standard normals. Integer and IEEE arithmetic only (plus `ln`, `sqrt`, `sin_cos`),
//! so a seed gives the same numbers on every platform and thread count. Used for the Monte
//! Carlo draws ([`crate::mc`], one stream per sample) and the readout noise of
//! [`crate::simulate`] (stream 0 of the run's seed); public so that tests draw their noise the
//! same way.

/// SplitMix64 finalizer: a bijective 64-bit mix.
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// xoshiro256** with a cached second Box-Muller variate.
#[derive(Debug, Clone)]
pub struct Rng {
    s: [u64; 4],
    spare: Option<f64>,
}

impl Rng {
    /// Stream `index` of run `seed`: SplitMix64 seeded by a mix of both, so streams of one
    /// seed (one per Monte Carlo sample, say) are independent and can be drawn in any order.
    pub fn stream(seed: u64, index: u64) -> Rng {
        let mut x = mix64(seed ^ mix64(index ^ 0x6A09_E667_F3BC_C909));
        let mut next = || {
            x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
            mix64(x)
        };
        let s = [next(), next(), next(), next()];
        Rng { s, spare: None }
    }

    fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let result = s[1].wrapping_mul(5).rotate_left(7).wrapping_mul(9);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// Uniform on [0, 1) with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Skips the next `count` values of [`Rng::gaussian`]: afterwards the generator returns
    /// exactly what it would have returned after `count` calls. Each Box-Muller pair consumes
    /// two raw draws, so the skip costs `count` raw draws and no logarithm or sine (a few
    /// nanoseconds per skipped value): the readout noise of a long simulation is drawn in
    /// chunks, each observable's part of the stream located by skipping the parts before it.
    pub fn skip_gaussians(&mut self, mut count: u64) {
        if count == 0 {
            return;
        }
        if self.spare.take().is_some() {
            count -= 1;
        }
        for _ in 0..(count / 2) * 2 {
            self.next_u64();
        }
        if count % 2 == 1 {
            self.gaussian();
        }
    }

    /// Standard normal (Box-Muller; the second variate of each pair is returned next).
    pub fn gaussian(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let u1 = 1.0 - self.uniform(); // (0, 1]: ln is finite
        let u2 = self.uniform();
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
        self.spare = Some(r * s);
        r * c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mean 0 and variance 1 within 5 standard errors (1/sqrt(n) for the mean, sqrt(2/n) for
    /// the variance), over many short streams (as the Monte Carlo draws them) and one long one
    /// (as the readout noise does).
    #[test]
    fn gaussian_moments() {
        let n = 200_000;
        let check = |z: &mut dyn FnMut(usize) -> f64| {
            let (mut s1, mut s2) = (0.0, 0.0);
            for i in 0..n {
                let v = z(i);
                s1 += v;
                s2 += v * v;
            }
            let mean = s1 / n as f64;
            let var = s2 / n as f64 - mean * mean;
            assert!(mean.abs() < 5.0 / (n as f64).sqrt(), "mean {mean}");
            assert!(
                (var - 1.0).abs() < 5.0 * (2.0 / n as f64).sqrt(),
                "var {var}"
            );
        };
        let mut short: Option<Rng> = None;
        check(&mut |i| {
            if i % 2 == 0 {
                short = Some(Rng::stream(7, i as u64 / 2));
            }
            short.as_mut().unwrap().gaussian()
        });
        let mut long = Rng::stream(7, 0);
        check(&mut |_| long.gaussian());
    }

    #[test]
    fn skipping_equals_drawing() {
        for (before, skip) in [
            (0, 0),
            (0, 1),
            (0, 2),
            (0, 7),
            (1, 0),
            (1, 1),
            (1, 4),
            (3, 6),
        ] {
            let mut drawn = Rng::stream(3, 0);
            let mut skipped = Rng::stream(3, 0);
            for _ in 0..before {
                drawn.gaussian();
                skipped.gaussian();
            }
            for _ in 0..skip {
                drawn.gaussian();
            }
            skipped.skip_gaussians(skip);
            for _ in 0..5 {
                assert_eq!(
                    drawn.gaussian().to_bits(),
                    skipped.gaussian().to_bits(),
                    "{before} drawn, {skip} skipped"
                );
            }
        }
    }

    #[test]
    fn streams_differ_and_repeat() {
        let draw = |seed, index| {
            let mut r = Rng::stream(seed, index);
            [r.uniform(), r.uniform()]
        };
        assert_eq!(draw(1, 2), draw(1, 2));
        assert_ne!(draw(1, 2), draw(1, 3));
        assert_ne!(draw(1, 2), draw(2, 2));
    }
}

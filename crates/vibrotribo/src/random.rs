//! A small counter-based random number generator (SplitMix64, Steele, Lea & Flood 2014) for
//! the library's reproducible random choices: a stream is named by a seed and indices (a
//! parameter value, a sample), so what a sample draws does not depend on which thread runs
//! it or in which order. Not for cryptography.

/// A SplitMix64 stream.
#[derive(Debug, Clone)]
pub(crate) struct SplitMix64 {
    state: u64,
}

const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

/// SplitMix64's output function (a bijective mix of 64 bits).
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl SplitMix64 {
    /// The stream of `seed` and the indices `path` (e.g. `[value index, sample index]`).
    pub fn stream(seed: u64, path: &[u64]) -> Self {
        let mut state = mix(seed.wrapping_add(GOLDEN));
        for &k in path {
            state = mix(state ^ mix(k.wrapping_add(GOLDEN).wrapping_mul(GOLDEN)));
        }
        SplitMix64 { state }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(GOLDEN);
        mix(self.state)
    }

    /// Uniform on [0, 1), 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u = 1.0 - self.uniform(); // (0, 1]
        let v = self.uniform();
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference sequence of SplitMix64 from state 0 (the algorithm's published test
    /// values: state += golden, then the mix).
    #[test]
    fn matches_the_reference_sequence() {
        let mut r = SplitMix64 { state: 0 };
        assert_eq!(r.next_u64(), 0xE220_A839_7B1D_CDAF);
        assert_eq!(r.next_u64(), 0x6E78_9E6A_A1B9_65F4);
        assert_eq!(r.next_u64(), 0x06C4_5D18_8009_454F);
    }

    #[test]
    fn uniform_moments_and_independent_streams() {
        let mut r = SplitMix64::stream(7, &[3, 4]);
        let n = 100_000;
        let xs: Vec<f64> = (0..n).map(|_| r.uniform()).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        assert!(
            (mean - 0.5).abs() < 5.0 * (1.0f64 / 12.0 / n as f64).sqrt(),
            "{mean}"
        );
        assert!((var - 1.0 / 12.0).abs() < 2e-3, "{var}");
        assert!(xs.iter().all(|x| (0.0..1.0).contains(x)));
        let a = SplitMix64::stream(7, &[3, 4]).next_u64();
        let b = SplitMix64::stream(7, &[4, 3]).next_u64();
        let c = SplitMix64::stream(8, &[3, 4]).next_u64();
        assert!(a != b && a != c && b != c);
    }
}

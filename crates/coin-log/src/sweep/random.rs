//! The random draws of a sweep: a counter-based generator from splitmix64, so that a run's values depend
//! only on the seed, the run's index and the draw's index. Its numbers are part of the contract, written
//! out here (not taken from a crate) as format.md defines them (Sweep files, Random draws, to the bit).
//!
//! Generator 2 mixes the seed before the run's index is added: generator 1 added them, so that seeds s
//! and s + k drew the same values k runs apart. A sweep's description names its generator, and a folder
//! of another generator is refused rather than resumed with other draws.

use crate::format::metadata::number_string;

/// The generator [`word`] implements, named in a sweep's description (format.md: sweep.json).
pub const GENERATOR: u64 = 2;

/// splitmix64's increment, ⌊2⁶⁴/φ⌋.
const GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// Attempts a bounded normal draw makes before it gives up: the bounds would have to hold less than
/// about one millionth of the distribution to reach it.
const NORMAL_ATTEMPTS: u64 = 1_000_000;

/// splitmix64's output function: a bijection of u64 that mixes every bit into every other.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

fn step(h: u64, x: u64) -> u64 {
    mix(h.wrapping_add(GAMMA).wrapping_add(x))
}

/// The `n`-th random word of draw `draw` of run `run`.
#[must_use]
pub fn word(seed: u64, run: u64, draw: u64, n: u64) -> u64 {
    step(step(step(step(0, seed), run), draw), n)
}

/// A word as a uniform number in [0, 1): its top 53 bits times 2⁻⁵³.
#[must_use]
#[allow(clippy::cast_precision_loss)] // below 2⁵³: exact
pub fn unit(word: u64) -> f64 {
    (word >> 11) as f64 * f64::EPSILON / 2.0
}

/// What one draw samples from (validated: finite bounds, lo < hi, 0 < lo for log-uniform, std > 0).
#[derive(Debug, Clone, PartialEq)]
pub enum Distribution {
    /// lo + (hi − lo)·u.
    Uniform { lo: f64, hi: f64 },
    /// exp(ln lo + (ln hi − ln lo)·u).
    LogUniform { lo: f64, hi: f64 },
    /// mean + std·z, z = √(−2 ln(1 − u₁))·cos(2π u₂) (Box–Muller), redrawn until within [min, max]
    /// (±∞ when not given).
    Normal {
        mean: f64,
        std: f64,
        min: f64,
        max: f64,
    },
    /// The k-th of `len` choices, k = ⌊(word >> 11)·len / 2⁵³⌋.
    Choice { len: usize },
}

/// What a draw gave: a number, or the index of a choice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Drawn {
    Number(f64),
    Choice(usize),
}

/// A bounded normal draw found no value within its bounds in [`NORMAL_ATTEMPTS`] attempts.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error(
    "no normal draw (mean {}, std {}) fell within [{}, {}] in {NORMAL_ATTEMPTS} attempts: widen the bounds",
    number_string(*mean), number_string(*std), number_string(*min), number_string(*max)
)]
pub struct OutOfBounds {
    pub mean: f64,
    pub std: f64,
    pub min: f64,
    pub max: f64,
}

impl Distribution {
    /// The value of draw `draw` of run `run`.
    pub fn draw(&self, seed: u64, run: u64, draw: u64) -> Result<Drawn, OutOfBounds> {
        let word = |n| word(seed, run, draw, n);
        Ok(match *self {
            Self::Uniform { lo, hi } => Drawn::Number(lo + (hi - lo) * unit(word(0))),
            Self::LogUniform { lo, hi } => {
                Drawn::Number((lo.ln() + (hi.ln() - lo.ln()) * unit(word(0))).exp())
            }
            Self::Normal {
                mean,
                std,
                min,
                max,
            } => {
                for attempt in 0..NORMAL_ATTEMPTS {
                    let (u1, u2) = (unit(word(2 * attempt)), unit(word(2 * attempt + 1)));
                    let z = (-2.0 * (1.0 - u1).ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
                    let x = mean + std * z;
                    if (min..=max).contains(&x) {
                        return Ok(Drawn::Number(x));
                    }
                }
                return Err(OutOfBounds {
                    mean,
                    std,
                    min,
                    max,
                });
            }
            Self::Choice { len } => {
                let k = (u128::from(word(0) >> 11) * len as u128) >> 53;
                // k < len ≤ usize::MAX by construction.
                Drawn::Choice(usize::try_from(k).unwrap_or(0))
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values computed independently (a 10-line Python transcription of format.md's definition).
    #[test]
    fn the_generator_gives_the_documented_words() {
        assert_eq!(
            mix(GAMMA),
            0xe220_a839_7b1d_cdaf,
            "splitmix64(0)'s first output"
        );
        let cases = [
            ((0, 0, 0, 0), 0x2130_748a_aac8_0268, 0.129_645_618_299_747_4),
            (
                (42, 0, 0, 0),
                0xc161_29ec_d0dc_5b93,
                0.755_388_851_467_487_9,
            ),
            (
                (42, 1, 0, 0),
                0x15f4_1633_3358_1662,
                0.085_755_717_754_494_98,
            ),
            (
                (42, 0, 1, 0),
                0x79ac_3b16_dbc3_b641,
                0.475_284_283_714_940_47,
            ),
            (
                (42, 0, 0, 1),
                0x6bd1_8687_32f4_640c,
                0.421_165_855_414_942_2,
            ),
            (
                ((1 << 63) - 1, 999, 3, 7),
                0x4988_aa24_143a_7af2,
                0.287_241_586_502_412_6,
            ),
        ];
        for ((seed, run, draw, n), expected, u) in cases {
            let w = word(seed, run, draw, n);
            assert_eq!(w, expected, "word({seed}, {run}, {draw}, {n}) = {w:#x}");
            assert_eq!(unit(w).to_bits(), f64::to_bits(u), "unit of {w:#x}");
        }
    }

    /// Neighbouring seeds draw apart: generator 1 (seed and run index added before mixing) gave seeds 1 and
    /// 2 the same draws one run apart, 1999 of 2000 (the control); generator 2 shares none.
    #[test]
    fn neighbouring_seeds_share_no_draws() {
        let shared = |word: &dyn Fn(u64, u64) -> u64| {
            let one: std::collections::HashSet<u64> = (0..2000).map(|i| word(1, i)).collect();
            (0..2000).filter(|&i| one.contains(&word(2, i))).count()
        };
        assert_eq!(shared(&|seed, run| step(step(step(seed, run), 0), 0)), 1999);
        assert_eq!(shared(&|seed, run| word(seed, run, 0, 0)), 0);
    }

    #[test]
    fn draws_stay_within_their_bounds_and_cover_them() {
        let uniform = Distribution::Uniform { lo: 2.0, hi: 3.0 };
        let log = Distribution::LogUniform { lo: 1e-3, hi: 1e3 };
        let normal = Distribution::Normal {
            mean: 0.0,
            std: 1.0,
            min: -0.5,
            max: 2.0,
        };
        let choice = Distribution::Choice { len: 3 };
        let mut seen = [0; 3];
        let (mut below_one, mut n) = (0, 0);
        for run in 0..2000 {
            let Ok(Drawn::Number(x)) = uniform.draw(7, run, 0) else {
                panic!()
            };
            assert!((2.0..=3.0).contains(&x), "{x}");
            let Ok(Drawn::Number(y)) = log.draw(7, run, 1) else {
                panic!()
            };
            assert!((1e-3..=1e3).contains(&y), "{y}");
            below_one += usize::from(y < 1.0);
            let Ok(Drawn::Number(z)) = normal.draw(7, run, 2) else {
                panic!()
            };
            assert!((-0.5..=2.0).contains(&z), "{z}");
            let Ok(Drawn::Choice(k)) = choice.draw(7, run, 3) else {
                panic!()
            };
            seen[k] += 1;
            n += 1;
        }
        // Log-uniform over six decades: half below 1; each choice about a third (4σ bounds).
        assert!(
            (900..1100).contains(&below_one),
            "{below_one} of {n} below 1"
        );
        assert!(seen.iter().all(|&c| (580..760).contains(&c)), "{seen:?}");
    }

    /// A normal draw whose bounds lie 10³⁰⁰ σ away fails after its attempts and says so, with its numbers
    /// short (`1e-300`, not 300 digits).
    #[test]
    fn a_normal_draw_with_unreachable_bounds_says_so() {
        let normal = Distribution::Normal {
            mean: 0.0,
            std: 1e-300,
            min: 1e10,
            max: 1e11,
        };
        let e = normal.draw(3, 0, 0).unwrap_err().to_string();
        assert_eq!(
            e,
            "no normal draw (mean 0.0, std 1e-300) fell within [10000000000.0, 100000000000.0] in \
                       1000000 attempts: widen the bounds"
        );
    }
}

//! The random draws of a sweep: a counter-based generator from splitmix64, so that a run's values depend
//! only on the seed, the run's index and the draw's index. Its numbers are part of the contract, written
//! out here (not taken from a crate) as format.md defines them (Sweep files, Random draws, to the bit).

use crate::format::metadata::number_string;

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
    step(step(step(seed, run), draw), n)
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
            (
                (0, 0, 0, 0),
                0x2382_75bc_38fc_be91,
                0.138_709_410_145_554_27,
            ),
            (
                (42, 0, 0, 0),
                0x6310_bf04_d820_7f46,
                0.386_974_276_240_040_9,
            ),
            (
                (42, 1, 0, 0),
                0x9bb6_c981_ed5e_f223,
                0.608_257_860_394_015_4,
            ),
            (
                (42, 0, 1, 0),
                0x2ce0_2c4e_e4d2_ea09,
                0.175_295_609_723_274_4,
            ),
            (
                (42, 0, 0, 1),
                0xb682_ee25_ce24_109e,
                0.712_935_337_285_799_4,
            ),
            (
                ((1 << 63) - 1, 999, 3, 7),
                0xb103_0064_3a16_ce5a,
                0.691_452_049_703_083_5,
            ),
        ];
        for ((seed, run, draw, n), expected, u) in cases {
            let w = word(seed, run, draw, n);
            assert_eq!(w, expected, "word({seed}, {run}, {draw}, {n}) = {w:#x}");
            assert_eq!(unit(w).to_bits(), f64::to_bits(u), "unit of {w:#x}");
        }
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

//! The stability map of the steady circles (format.md: analyse; physics §9): σ² over a grid of (θ₀, ω_Z0)
//! on either branch of the steady family, the boundary σ² = 0 in closed form (eqs (22)–(24)), where the
//! band of unstable circles closes, and the built-in scenes' steady motions on the map.

use super::steady::{Stability, SteadyAnalysis};
use crate::model::{
    critical_spin, steady_omega_y, steady_sigma_squared, Branch, Coin, Linearisation,
};
use crate::scene::{self, presets, InitialSpec, Scene, Short};
use std::f64::consts::FRAC_PI_2;
use std::fmt::Write as _;
use std::str::FromStr;
use thiserror::Error;

/// Most grid points per axis.
pub const MAX_COUNT: usize = 10_000;
/// Most grid points in all (θ₀ × ω_Z0 × branches): 4 million points are 250 MB of CSV.
pub const MAX_POINTS: usize = 4_000_000;

/// Why a map cannot be made.
#[derive(Debug, Clone, PartialEq, Error)]
#[allow(missing_docs, reason = "each field is named in its variant's doc")]
pub enum MapError {
    /// A grid `flag` (`--theta`, `--omega-z`) whose `value` does not parse or is out of range: the
    /// `reason` says what is wrong and what would do.
    #[error("`{flag} {value}`: {reason}")]
    Grid {
        flag: &'static str,
        value: String,
        reason: String,
    },
    /// More `points` (θ₀ count × ω_Z0 count × branches) than [`MAX_POINTS`].
    #[error("{points} grid points is more than {MAX_POINTS}: use fewer points per axis")]
    TooLarge { points: usize },
    /// A grid point (fields as in [`MapPoint`], the branch by name) whose ω_Y0 or σ² is not a finite
    /// number in double precision.
    #[error("the circle θ0 = {}, ω_Z0 = {} ({branch} branch) gives ω_Y0 = {}, σ² = {}: too fast, too near upright or too near flat for double precision; narrow --theta or --omega-z", Short(*theta0), Short(*omega_z0), Short(*omega_y0), Short(*sigma_squared))]
    NonFinite {
        theta0: f64,
        omega_z0: f64,
        branch: &'static str,
        omega_y0: f64,
        sigma_squared: f64,
    },
    /// `--branch` other than `+`, `-` or `both`.
    #[error("`--branch {0}`: use `+`, `-` or `both`")]
    Branch(String),
    /// Drawing the SVG failed.
    #[error("drawing the stability map: {0}")]
    Plot(String),
}

/// `A:B:N`: N = `count` values (1 ..= [`MAX_COUNT`]) from A = `from` to B = `to`, equally spaced (N = 1:
/// A alone).
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct Grid {
    pub from: f64,
    pub to: f64,
    pub count: usize,
}

impl Grid {
    /// Parses `A:B:N` given to `flag`, or fails ([`MapError::Grid`]) naming the flag, the value and the
    /// expected form.
    pub fn parse(flag: &'static str, text: &str) -> Result<Self, MapError> {
        let error = |reason: String| MapError::Grid {
            flag,
            value: text.to_string(),
            reason,
        };
        let parts: Vec<&str> = text.split(':').map(str::trim).collect();
        let [from, to, count] = parts[..] else {
            return Err(error(
                "expected A:B:N, e.g. `0.01:1.5:200` (N values from A to B)".into(),
            ));
        };
        let number = |s: &str, what: &str| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| error(format!("{what} `{s}` is not a finite number")))
        };
        let (from, to) = (number(from, "A")?, number(to, "B")?);
        if !(to - from).is_finite() {
            return Err(error(format!(
                "B − A = {} overflows double precision; give A and B nearer each other",
                to - from
            )));
        }
        let count = count
            .parse::<usize>()
            .ok()
            .filter(|n| (1..=MAX_COUNT).contains(n))
            .ok_or_else(|| {
                error(format!(
                    "N `{count}` is not a whole number from 1 to {MAX_COUNT}"
                ))
            })?;
        Ok(Self { from, to, count })
    }

    /// Value number `i` (0-based).
    #[must_use]
    pub fn value(&self, i: usize) -> f64 {
        if self.count == 1 {
            return self.from;
        }
        #[allow(clippy::cast_precision_loss)]
        let x = i as f64 / (self.count - 1) as f64;
        self.from + (self.to - self.from) * x
    }

    /// The spacing between values (the whole span for one value, or 0 when A = B).
    #[must_use]
    pub fn step(&self) -> f64 {
        #[allow(clippy::cast_precision_loss)]
        let gaps = self.count.saturating_sub(1).max(1) as f64;
        (self.to - self.from).abs() / gaps
    }

    /// The smallest and largest value.
    #[must_use]
    pub fn bounds(&self) -> (f64, f64) {
        (self.from.min(self.to), self.from.max(self.to))
    }
}

impl std::fmt::Display for Grid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (from, to) = (Short(self.from), Short(self.to));
        write!(f, "{from}:{to}:{}", self.count)
    }
}

/// Which branches a map covers: the + root only, the − root only, or both.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs, reason = "the enum's doc names each variant")]
pub enum Branches {
    Plus,
    Minus,
    Both,
}

impl Branches {
    /// The branches, + first.
    #[must_use]
    pub fn list(self) -> &'static [Branch] {
        match self {
            Self::Plus => &[Branch::Plus],
            Self::Minus => &[Branch::Minus],
            Self::Both => Branch::ALL,
        }
    }

    /// The names `from_str` takes, as `--branch` offers them (`plus` and `minus` are read too).
    pub const NAMES: &'static [&'static str] = &["+", "-", "both"];
}

impl FromStr for Branches {
    type Err = MapError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "+" | "plus" => Ok(Self::Plus),
            "-" | "minus" => Ok(Self::Minus),
            "both" => Ok(Self::Both),
            other => Err(MapError::Branch(other.to_string())),
        }
    }
}

/// The grid of a map: the θ₀ values `theta` \[rad\], each 0 < |θ₀| < π/2, the ω_Z0 values `omega_z`
/// [rad/time], and the roots of the steady family, `branches`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct MapOptions {
    pub theta: Grid,
    pub omega_z: Grid,
    pub branches: Branches,
}

/// The default θ₀ grid of `analyse map`.
pub const DEFAULT_THETA: &str = "0.0075:1.5:200";
/// The default ω_Z0 grid of `analyse map`.
pub const DEFAULT_OMEGA_Z: &str = "0:2:200";

impl MapOptions {
    /// Checks the grid: every θ₀ leaning (0 < |θ₀| < π/2), at most [`MAX_POINTS`] points, or fails
    /// naming the flag and the allowed range.
    pub fn validate(&self) -> Result<(), MapError> {
        let (lo, hi) = self.theta.bounds();
        let leaning = |t: f64| t != 0.0 && t.abs() < FRAC_PI_2;
        let crosses_zero = lo < 0.0 && hi > 0.0 && self.theta.count > 1;
        let zero_on_grid = (0..self.theta.count).any(|i| !leaning(self.theta.value(i)));
        if !leaning(lo) || !leaning(hi) || crosses_zero || zero_on_grid {
            return Err(MapError::Grid {
                flag: "--theta",
                value: self.theta.to_string(),
                reason: "every θ0 must lean: 0 < |θ0| < π/2 (upright θ0 = 0 is straight rolling or the upright spin, physics §4.1, §4.5; on one side of 0)".into(),
            });
        }
        let points = self.theta.count * self.omega_z.count * self.branches.list().len();
        if points > MAX_POINTS {
            return Err(MapError::TooLarge { points });
        }
        Ok(())
    }
}

impl Default for MapOptions {
    fn default() -> Self {
        // The defaults parse: they are the constants above.
        let grid = |flag, text| {
            Grid::parse(flag, text).unwrap_or(Grid {
                from: 0.5,
                to: 0.5,
                count: 1,
            })
        };
        Self {
            theta: grid("--theta", DEFAULT_THETA),
            omega_z: grid("--omega-z", DEFAULT_OMEGA_Z),
            branches: Branches::Both,
        }
    }
}

/// One steady circle of the map: the lean `theta0` \[rad\], the spin `omega_z0` and, on the root `branch`
/// of the steady family, `omega_y0` [rad/time], its σ² of eq (21) `sigma_squared` [1/time²] and its
/// `verdict`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct MapPoint {
    pub theta0: f64,
    pub omega_z0: f64,
    pub branch: Branch,
    pub omega_y0: f64,
    pub sigma_squared: f64,
    pub verdict: Stability,
}

/// A steady circle with σ² = 0: `theta0`, `omega_z0`, `omega_y0` and `branch` as in [`MapPoint`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct BoundaryPoint {
    pub theta0: f64,
    pub omega_z0: f64,
    pub omega_y0: f64,
    pub branch: Branch,
}

/// A built-in (or the given) scene's steady motion on the map: the scene's `name`, `theta0` \[rad\] (0
/// for straight rolling and the upright spin), `omega_z0` in the map body's units [rad/time], the
/// `branch` whose panel shows it (straight rolling: the root it continues) and its `verdict`.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct ScenePoint {
    pub name: String,
    pub theta0: f64,
    pub omega_z0: f64,
    pub branch: Branch,
    pub verdict: Stability,
}

/// The stability map of the body `coin` over the grid `options`: its `points` (θ₀-major, then ω_Z0,
/// then branch, + first), ω_c of straight rolling (`critical_spin`, physics §5), the `closures` where
/// the two edges of an unstable band meet (the folds of the boundary) and the `scenes`' steady motions.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct StabilityMap {
    pub coin: Coin,
    pub options: MapOptions,
    pub points: Vec<MapPoint>,
    pub critical_spin: f64,
    pub closures: Vec<BoundaryPoint>,
    pub scenes: Vec<ScenePoint>,
}

/// σ² and its verdict for the circle (θ₀, ω_Z0) on `branch`; fails ([`MapError::NonFinite`]) where ω_Y0
/// or σ² overflows (σ² grows as ω_Z0² tan²θ₀: ω_Z0 = 1e154 made it `inf` and the − branch `NaN`, which
/// the CSV would have called "marginal" and "unstable").
fn map_point(
    coin: &Coin,
    theta0: f64,
    omega_z0: f64,
    branch: Branch,
) -> Result<MapPoint, MapError> {
    let omega_y0 = steady_omega_y(coin, theta0, omega_z0, branch);
    let sigma_squared = steady_sigma_squared(coin, theta0, omega_y0, omega_z0);
    let scale = Linearisation::at(coin, theta0, omega_y0, omega_z0).scale();
    if !(omega_y0.is_finite() && sigma_squared.is_finite() && scale.is_finite()) {
        return Err(MapError::NonFinite {
            theta0,
            omega_z0,
            branch: branch.name(),
            omega_y0,
            sigma_squared,
        });
    }
    Ok(MapPoint {
        theta0,
        omega_z0,
        branch,
        omega_y0,
        sigma_squared,
        verdict: Stability::of(sigma_squared, scale),
    })
}

/// The map over `options`' grid for `coin`, with the built-in scenes of the same shape and `extra` (a
/// scene of the caller's) placed on it. Fails for a grid that [`MapOptions::validate`] refuses, or a
/// circle of it that double precision cannot hold ([`MapError::NonFinite`]).
pub fn stability_map(
    coin: &Coin,
    options: &MapOptions,
    extra: Option<(&str, &Scene)>,
) -> Result<StabilityMap, MapError> {
    options.validate()?;
    let branches = options.branches.list();
    let mut points =
        Vec::with_capacity(options.theta.count * options.omega_z.count * branches.len());
    for i in 0..options.theta.count {
        let theta0 = options.theta.value(i);
        for j in 0..options.omega_z.count {
            let omega_z0 = options.omega_z.value(j);
            for &branch in branches {
                points.push(map_point(coin, theta0, omega_z0, branch)?);
            }
        }
    }
    Ok(StabilityMap {
        coin: *coin,
        options: *options,
        points,
        critical_spin: critical_spin(coin),
        closures: closures(coin),
        scenes: scene_points(coin, extra),
    })
}

impl StabilityMap {
    /// `stability-map.csv`: the header `theta0,omega_z0,branch,omega_y0,sigma_squared,verdict` and one
    /// line per point, numbers as shortest round-trip decimals.
    #[must_use]
    pub fn csv(&self) -> String {
        let mut line = crate::csv::Line::default();
        line.text("theta0").text("omega_z0").text("branch");
        line.text("omega_y0").text("sigma_squared").text("verdict");
        for p in &self.points {
            line.finish();
            line.number(p.theta0)
                .number(p.omega_z0)
                .text(p.branch.name());
            line.number(p.omega_y0)
                .number(p.sigma_squared)
                .text(p.verdict.name());
        }
        line.finish().to_string()
    }

    /// Points of the grid that are unstable.
    #[must_use]
    pub fn unstable_count(&self) -> usize {
        self.points
            .iter()
            .filter(|p| p.verdict == Stability::Unstable)
            .count()
    }

    /// The points of one θ₀ column on one branch, in ω_Z0 order.
    pub fn column(&self, i: usize, branch: Branch) -> impl Iterator<Item = &MapPoint> {
        let per_theta = self.options.omega_z.count * self.options.branches.list().len();
        self.points[i * per_theta..(i + 1) * per_theta]
            .iter()
            .filter(move |p| p.branch == branch)
    }
}

/// Every steady circle with σ² = 0 at lean θ₀, in closed form (module doc): for each real root r of P
/// with ω_Z0² > 0, both signs of ω_Z0, each on the branch whose ω_Y0 it is. Empty at θ₀ = 0.
#[must_use]
pub fn boundary(coin: &Coin, theta0: f64) -> Vec<BoundaryPoint> {
    let p = coin.params();
    let (ix, iz, ma2) = (p.inertia_x(), p.inertia_z(), p.ma2());
    let mga = p.energy_scale();
    let (s, c) = theta0.sin_cos();
    let t = s / c;
    if t == 0.0 || !t.is_finite() {
        return Vec::new();
    }
    let qa = 3.0 * ix * t * t + ma2;
    let qb = (3.0 * iz + ma2) * t - (iz + ma2) / t;
    let qc = iz * (iz + ma2) / ix;
    let mut out = Vec::new();
    for r in real_roots(qa, qb, qc) {
        let omega2 = mga * s / (r * (ix * t * r + iz + ma2));
        if !(omega2.is_finite() && omega2 > 0.0) {
            continue;
        }
        for omega_z0 in [omega2.sqrt(), -omega2.sqrt()] {
            out.push(on_branch(coin, theta0, omega_z0, r * omega_z0));
        }
    }
    out
}

/// The boundary point (θ₀, ω_Z0, ω_Y0) with the branch whose root ω_Y0 is.
pub(super) fn on_branch(coin: &Coin, theta0: f64, omega_z0: f64, omega_y0: f64) -> BoundaryPoint {
    BoundaryPoint {
        theta0,
        omega_z0,
        omega_y0,
        branch: Branch::nearest(coin, theta0, omega_z0, omega_y0),
    }
}

/// The real roots of a x² + b x + c (none when the discriminant is negative) by the stable quadratic
/// formula: q = −(b + sgn(b)√D)/2, roots q/a and c/q.
fn real_roots(a: f64, b: f64, c: f64) -> Vec<f64> {
    let d = b * b - 4.0 * a * c;
    if d < 0.0 {
        return Vec::new();
    }
    let q = -0.5 * (b + b.signum() * d.sqrt());
    vec![q / a, c / q]
}

/// Where the two roots of P meet, θ₀ > 0 and ω_Z0 > 0: the leans where a band of unstable circles closes,
/// the roots u = tan²θ₀ of eq (24) (physics §9). The mirror images (−θ₀, −ω_Z0) are closures too.
#[must_use]
pub fn closures(coin: &Coin) -> Vec<BoundaryPoint> {
    let p = coin.params();
    let (ix, iz, ma2) = (p.inertia_x(), p.inertia_z(), p.ma2());
    let k = iz + ma2;
    let a = ma2 * ma2 - 6.0 * iz * ma2 - 3.0 * iz * iz;
    let b = -2.0 * k * (3.0 * iz + ma2 + 2.0 * ma2 * iz / ix);
    let c = k * k;
    let roots = if a == 0.0 {
        vec![-c / b]
    } else {
        real_roots(a, b, c)
    };
    let mga = p.energy_scale();
    roots
        .into_iter()
        .filter(|u| u.is_finite() && *u > 0.0)
        .filter_map(|u| {
            let t = u.sqrt();
            let theta0 = t.atan();
            // The double root of P.
            let r = -((3.0 * iz + ma2) * t - k / t) / (2.0 * (3.0 * ix * t * t + ma2));
            let omega2 = mga * theta0.sin() / (r * (ix * t * r + k));
            (omega2.is_finite() && omega2 > 0.0).then(|| {
                let omega_z0 = omega2.sqrt();
                on_branch(coin, theta0, omega_z0, r * omega_z0)
            })
        })
        .collect()
}

/// A few round leans below the highest closure (steps of 1, 2 or 5 × 10ⁿ, about six of them) at which
/// to report the band's edges; the leans 0.05 … 0.3 for the thin disk.
#[must_use]
pub fn edge_leans(coin: &Coin) -> Vec<f64> {
    let Some(top) = closures(coin).iter().map(|c| c.theta0).reduce(f64::max) else {
        return Vec::new();
    };
    let rough = top / 6.0;
    let decade = 10f64.powf(rough.log10().floor());
    let multiple = [5.0, 2.0, 1.0]
        .into_iter()
        .find(|m| m * decade <= rough)
        .unwrap_or(1.0);
    // (i·m)·10ⁿ rather than i·(m·10ⁿ): 0.15, not 0.15000000000000002.
    (1..=12)
        .map(|i| f64::from(i) * multiple * decade)
        .take_while(|t| *t < top)
        .collect()
}

/// The steady motions of the built-in scenes whose body has the map body's shape (the same I_X/Ma² and
/// I_Z/Ma²), in the map's units (ω scaled by the ratio of the time units), and `extra`'s.
fn scene_points(coin: &Coin, extra: Option<(&str, &Scene)>) -> Vec<ScenePoint> {
    let mut scenes: Vec<(String, Scene)> = presets::NAMES
        .iter()
        .filter_map(|name| {
            let file = presets::preset(name)?;
            let scene = scene::resolve(&file, &scene::FlagOverrides::default()).ok()?;
            Some(((*name).to_string(), scene))
        })
        .collect();
    if let Some((name, scene)) = extra {
        if !scenes.iter().any(|(n, _)| n == name) {
            scenes.push((name.to_string(), scene.clone()));
        }
    }
    let p = coin.params();
    let shape = |c: &crate::model::CoinParams| (c.inertia_x() / c.ma2(), c.inertia_z() / c.ma2());
    let (sx, sz) = shape(p);
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs());
    scenes
        .into_iter()
        .filter_map(|(name, scene)| {
            let (kx, kz) = shape(&scene.params);
            if !(same(kx, sx) && same(kz, sz)) {
                return None;
            }
            let InitialSpec::Steady(steady) = scene.spec else {
                return None;
            };
            let s = steady.state;
            let scale = scene.params.time_unit() / p.time_unit();
            let analysis = SteadyAnalysis::of_state(&scene.coin(), &s, Some(&steady));
            // Straight rolling continues the + root for ω_Z0 > 0 and the − root for ω_Z0 < 0; the upright
            // spin is the centre-fixed motion's limit, on the branch of the sign of ω_Y0.
            let branch = steady
                .kind
                .branch()
                .unwrap_or(if s.omega_y < 0.0 || s.omega_z < 0.0 {
                    Branch::Minus
                } else {
                    Branch::Plus
                });
            Some(ScenePoint {
                name,
                theta0: s.theta,
                omega_z0: s.omega_z * scale,
                branch,
                verdict: analysis.verdict,
            })
        })
        .collect()
}

/// One line per closure and per edge lean: the band's edges as text, for the command's summary.
#[must_use]
pub fn band_report(coin: &Coin) -> String {
    let mut out = String::new();
    for lean in edge_leans(coin) {
        let spins: Vec<String> = boundary(coin, lean)
            .iter()
            .filter(|b| b.omega_z0 > 0.0)
            .map(|b| format!("{:.6} ({} branch)", b.omega_z0, b.branch))
            .collect();
        let _ = writeln!(out, "  θ0 = {lean}: σ² = 0 at ω_Z0 = {}", spins.join(", "));
    }
    for c in closures(coin) {
        let _ = writeln!(
            out,
            "  closes at θ0 = {:.6}, ω_Z0 = {:.6} ({} branch)",
            c.theta0, c.omega_z0, c.branch
        );
    }
    out
}

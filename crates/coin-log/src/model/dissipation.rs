//! Dissipation (physics §11): a couple −P ω/|ω|² on the coin, with power P = κ |φ̇|^m (sin α)^(−k),
//! α = π/2 − |θ| the angle between the coin and the table, and the dissipated work W as a ninth state
//! component (Ẇ = P), so that E + W = E₀ holds along the equations (eqs (30)–(34)). [`Coin`] stays as it
//! is: a dissipative run integrates [`DissipativeCoin`] (see `simulation`).

use super::derived::{reaction_with, Reaction};
use super::equations::{kinematics, AngularAcceleration, Coin};
use super::state::{State, STATE_LEN};
use thiserror::Error;

/// Number of state components of the dissipative coin: the eight of [`State`] and the dissipated work W.
pub const DISSIPATIVE_STATE_LEN: usize = STATE_LEN + 1;

/// Index of W in the dissipative state.
pub const WORK_INDEX: usize = STATE_LEN;

coin_log_names::named_enum! {
    /// A dissipation law by name (format.md: `body.dissipation.model`, in the order of its table): the
    /// exponents m, k of P = κ |φ̇|^m (sin α)^(−k) (physics §11).
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    pub enum DissipationModel: "dissipation model" {
        /// Moffatt's viscous air film under the coin: m = 2, k = 1 (α ∝ (t₀ − t)^{1/3}).
        Moffatt = "moffatt",
        /// Air drag in a viscous boundary layer (Bildsten): m = 2.5, k = 0 (α ∝ (t₀ − t)^{4/9}).
        AirDrag = "air-drag",
        /// A couple linear in the rate, P ∝ φ̇²: m = 2, k = 0 (α ∝ (t₀ − t)^{1/2}).
        Viscous = "viscous",
        /// Rolling resistance, a constant resisting force at the rim: m = 1, k = 0 (α ∝ (t₀ − t)^{2/3}).
        Rolling = "rolling",
        /// Pivoting (drilling) friction of Le Saux, Leine & Glocker (2005), a Coulomb torque about the
        /// table normal, in the form it takes on the centre-fixed motion: m = 1, k = −2 (no finite-time
        /// singularity).
        Pivoting = "pivoting",
        /// Any exponents: `m` and `k` given in the scene.
        PowerLaw = "power-law",
    }
}

impl DissipationModel {
    /// The models with fixed exponents: every one but `power-law`, the last.
    pub const PRESETS: &'static [DissipationModel] = Self::ALL.split_at(Self::ALL.len() - 1).0;

    /// The fixed exponents (m, k) of a preset; `None` for `power-law`.
    #[must_use]
    pub fn exponents(self) -> Option<(f64, f64)> {
        match self {
            Self::Moffatt => Some((2.0, 1.0)),
            Self::AirDrag => Some((2.5, 0.0)),
            Self::Viscous => Some((2.0, 0.0)),
            Self::Rolling => Some((1.0, 0.0)),
            Self::Pivoting => Some((1.0, -2.0)),
            Self::PowerLaw => None,
        }
    }
}

/// Smallest exponent m: with m ≥ 1 the couple's magnitude P/|ω| ≤ κ |ω|^(m−1) (cos θ)^(−m−k) stays
/// bounded as the coin stops (|ω| → 0); below 1 it would grow without bound (physics §11).
pub const MIN_RATE_EXPONENT: f64 = 1.0;

/// Why a dissipation cannot be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum DissipationError {
    /// κ is negative or not finite.
    #[error("the coefficient κ = {0} must be a finite number ≥ 0")]
    Coefficient(f64),
    /// m is below 1 or not finite.
    #[error("m = {0} must be a finite number ≥ 1 (the couple P/|ω| ∝ |ω|^(m−1) must stay bounded as the coin stops)")]
    RateExponent(f64),
    /// k is not finite.
    #[error("k = {0} must be a finite number")]
    AngleExponent(f64),
}

/// A validated dissipation law: model, κ ≥ 0, m ≥ 1, k finite (physics §11).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dissipation {
    model: DissipationModel,
    coefficient: f64,
    m: f64,
    k: f64,
}

impl Dissipation {
    /// A preset's law with coefficient κ (the preset fixes m and k); fails for a bad κ: `power-law` has
    /// no fixed exponents and is refused as m = NaN.
    ///
    /// ```
    /// use coin_log::model::{Dissipation, DissipationModel};
    /// let d = Dissipation::preset(DissipationModel::Moffatt, 1e-6).unwrap();
    /// assert_eq!((d.m(), d.k(), d.angle_exponent()), (2.0, 1.0, -2.0));
    /// assert_eq!(d.predicted_exponent(), 1.0 / 3.0);
    /// ```
    pub fn preset(model: DissipationModel, coefficient: f64) -> Result<Self, DissipationError> {
        let (m, k) = model.exponents().unwrap_or((f64::NAN, f64::NAN));
        Self::new(model, coefficient, m, k)
    }

    /// A law with explicit exponents (`power-law`, or a preset with its own m, k); fails naming the first
    /// bad value.
    pub fn new(
        model: DissipationModel,
        coefficient: f64,
        m: f64,
        k: f64,
    ) -> Result<Self, DissipationError> {
        if !(coefficient.is_finite() && coefficient >= 0.0) {
            return Err(DissipationError::Coefficient(coefficient));
        }
        if !(m.is_finite() && m >= MIN_RATE_EXPONENT) {
            return Err(DissipationError::RateExponent(m));
        }
        if !k.is_finite() {
            return Err(DissipationError::AngleExponent(k));
        }
        Ok(Self {
            model,
            coefficient,
            m,
            k,
        })
    }

    getters! {
        /// The model.
        model: DissipationModel,
        /// κ [energy·time^(1−m)], the scene's `coefficient`.
        coefficient: f64,
        /// m, the exponent of |φ̇|.
        m: f64,
        /// k, the exponent of 1/sin α.
        k: f64,
    }

    /// p = −m/2 − k: along the centre-fixed family P ∝ (sin α)^p (physics §11, eq (36)).
    #[must_use]
    pub fn angle_exponent(&self) -> f64 {
        -0.5 * self.m - self.k
    }

    /// n = 1/(1 − p) of the law α ∝ |t₀ − t|^n (physics §11.2): a finite-time collapse at t₀ for p < 1
    /// (eq (38)), an algebraic decay (n < 0) for p > 1, an exponential one (n infinite) for p = 1.
    #[must_use]
    pub fn predicted_exponent(&self) -> f64 {
        1.0 / (1.0 - self.angle_exponent())
    }

    /// The dissipated power P = κ |φ̇|^m (sin α)^(−k) at lean θ and ω_Y (eq (34)), with φ̇ = ω_Y / cos θ
    /// (eq (18)) and sin α = cos θ: finite wherever the rolling model is (|θ| < π/2, the run ends at the flat
    /// landing) and P is below the largest double, 0 when ω_Y = 0 (m ≥ 1). A factor may overflow where the
    /// product does not: (sin α)^(−k) of k = 400 is infinite below α = 0.18, which made P = 0·∞ = NaN on a
    /// coin released without spin (`topple` ended "non-finite" at α = 0.18 with W = 0). So P is 0 when
    /// |φ̇|^m is, and a product that overflowed is taken by its logarithm; elsewhere it is as it always was.
    #[must_use]
    #[inline]
    pub fn power(&self, theta: f64, omega_y: f64) -> f64 {
        let cos_t = theta.cos();
        let phi_dot = omega_y / cos_t;
        let rate_factor = phi_dot.abs().powf(self.m);
        if rate_factor == 0.0 {
            return 0.0;
        }
        let power = self.coefficient * rate_factor * cos_t.powf(-self.k);
        if power.is_finite() {
            return power;
        }
        (self.coefficient.ln() + self.m * phi_dot.abs().ln() - self.k * cos_t.ln()).exp()
    }
}

/// The coin with a dissipative couple: eqs (30)–(34) of physics §11 on the state (θ, φ, ψ, ω, x, z, W).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DissipativeCoin {
    coin: Coin,
    dissipation: Dissipation,
    /// 1/(I_X + Ma²), eq (31).
    inv_x: f64,
    /// 1/I_X, eq (32).
    inv_y: f64,
    /// 1/(I_Z + Ma²), eq (33).
    inv_z: f64,
}

/// The couple's effect at one state: the angular accelerations of eqs (31)–(33) and the power P.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DissipativeRates {
    /// (ω̇_X, ω̇_Y, ω̇_Z) with the couple.
    pub acceleration: AngularAcceleration,
    /// P = Ẇ ≥ 0 (eq (34)).
    pub power: f64,
}

impl DissipativeCoin {
    /// The coin `coin` with the couple of `dissipation`.
    #[must_use]
    pub fn new(coin: Coin, dissipation: Dissipation) -> Self {
        let p = coin.params();
        let ma2 = p.ma2();
        Self {
            coin,
            dissipation,
            inv_x: 1.0 / (p.inertia_x() + ma2),
            inv_y: 1.0 / p.inertia_x(),
            inv_z: 1.0 / (p.inertia_z() + ma2),
        }
    }

    /// The conservative coin underneath.
    #[must_use]
    pub fn coin(&self) -> &Coin {
        &self.coin
    }

    /// The dissipation law.
    #[must_use]
    pub fn dissipation(&self) -> &Dissipation {
        &self.dissipation
    }

    /// Angular accelerations of eqs (31)–(33) and the power P of eq (34) (physics §11.1); at ω = 0 the
    /// couple is 0 (P = 0 there, since m ≥ 1).
    #[must_use]
    #[inline]
    pub fn rates(&self, theta: f64, omega_x: f64, omega_y: f64, omega_z: f64) -> DissipativeRates {
        let conservative = self
            .coin
            .angular_acceleration(theta, omega_x, omega_y, omega_z);
        let power = self.dissipation.power(theta, omega_y);
        let w2 = omega_x * omega_x + omega_y * omega_y + omega_z * omega_z;
        let couple = if w2 > 0.0 { power / w2 } else { 0.0 };
        DissipativeRates {
            acceleration: AngularAcceleration {
                x: conservative.x - couple * omega_x * self.inv_x,
                y: conservative.y - couple * omega_y * self.inv_y,
                z: conservative.z - couple * omega_z * self.inv_z,
            },
            power,
        }
    }

    /// The right-hand side: eqs (17)–(19), (31)–(34) and the centre's velocity (physics §2, §11). The
    /// couple changes only ω̇; the kinematics and the rolling constraint are those of the conservative coin.
    #[inline]
    pub fn derivative(
        &self,
        y: &[f64; DISSIPATIVE_STATE_LEN],
        dydt: &mut [f64; DISSIPATIVE_STATE_LEN],
    ) {
        let rates = self.rates(y[0], y[3], y[4], y[5]);
        kinematics(self.coin.params().radius(), y, dydt);
        dydt[3] = rates.acceleration.x; // (31)
        dydt[4] = rates.acceleration.y; // (32)
        dydt[5] = rates.acceleration.z; // (33)
        dydt[WORK_INDEX] = rates.power; // (34)
    }
}

/// How the coin moves: conservative (eqs (14)–(19)) or with a dissipative couple (eqs (30)–(34)). The
/// one choice a scene makes; every per-state quantity that depends on ω̇ (the reaction) goes through it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Dynamics {
    /// No dissipation: E, C1, C2 are conserved.
    Conservative(Coin),
    /// A dissipative couple: E + W is conserved.
    Dissipative(DissipativeCoin),
}

impl From<Coin> for Dynamics {
    fn from(coin: Coin) -> Self {
        Self::Conservative(coin)
    }
}

impl From<DissipativeCoin> for Dynamics {
    fn from(coin: DissipativeCoin) -> Self {
        Self::Dissipative(coin)
    }
}

impl Dynamics {
    /// The dynamics of `coin` with an optional dissipation.
    #[must_use]
    pub fn new(coin: Coin, dissipation: Option<Dissipation>) -> Self {
        match dissipation {
            None => Self::Conservative(coin),
            Some(d) => Self::Dissipative(DissipativeCoin::new(coin, d)),
        }
    }

    /// The coin (parameters and conservative equations).
    #[must_use]
    pub fn coin(&self) -> &Coin {
        match self {
            Self::Conservative(c) => c,
            Self::Dissipative(d) => d.coin(),
        }
    }

    /// The dissipation law, if any.
    #[must_use]
    pub fn dissipation(&self) -> Option<&Dissipation> {
        match self {
            Self::Conservative(_) => None,
            Self::Dissipative(d) => Some(d.dissipation()),
        }
    }

    /// (ω̇_X, ω̇_Y, ω̇_Z) at a state: eqs (14)–(16), or (31)–(33) with the couple.
    #[must_use]
    pub fn angular_acceleration(&self, s: &State) -> AngularAcceleration {
        let (theta, wx, wy, wz) = (s.theta, s.omega_x, s.omega_y, s.omega_z);
        match self {
            Self::Conservative(c) => c.angular_acceleration(theta, wx, wy, wz),
            Self::Dissipative(d) => d.rates(theta, wx, wy, wz).acceleration,
        }
    }

    /// The table's reaction at a state (physics §3, §11): the couple is a pure torque, so R = M dv/dt +
    /// Mg e_y as without it, but dv/dt follows the dissipative ω̇.
    #[must_use]
    pub fn reaction(&self, s: &State) -> Reaction {
        reaction_with(self.coin(), s, self.angular_acceleration(s))
    }
}

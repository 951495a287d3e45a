//! The rolling coin: parameters, state, equations of motion and derived quantities (physics §1–§6).
//! Pure functions; no I/O and no knowledge of integrators or files.

/// Getters that return a field by value: `getters! { /// Its doc. name: Type, ... }`.
macro_rules! getters {
    ($($(#[$attr:meta])* $name:ident: $ty:ty),* $(,)?) => {$(
        $(#[$attr])*
        #[must_use]
        pub fn $name(&self) -> $ty {
            self.$name
        }
    )*};
}

mod derived;
mod dissipation;
pub mod drift;
mod equations;
pub mod fit;
mod invariants;
pub mod nutation;
mod params;
pub mod quadrature;
mod stability;
mod state;
mod steady;
mod turning_points;

pub use derived::{centre, contact_point, energy, orientation, reaction, Energy, Reaction};
pub use dissipation::{
    Dissipation, DissipationError, DissipationModel, DissipativeCoin, DissipativeRates, Dynamics,
    DISSIPATIVE_STATE_LEN, MIN_RATE_EXPONENT, WORK_INDEX,
};
pub use equations::{AngularAcceleration, Coin};
pub use invariants::{Chaplygin, Invariants, InvariantsError, LegendreBasis};
pub use params::{CoinParams, Inertia, ParamError};
pub use stability::{
    centre_fixed_sigma_squared, critical_spin, eigenvalues, spin_upright_sigma_squared,
    steady_sigma_squared, straight_lambda_squared, Linearisation,
};
pub use state::{magnitude, State, StateRate, STATE_LEN};
pub use steady::{steady_omega_y, Branch, Steady, SteadyError, SteadyFamily, SteadyKind};
pub use turning_points::{MeasuredNutation, TurningPoints};

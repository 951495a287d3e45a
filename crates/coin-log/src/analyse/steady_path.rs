//! The exact path of a steady motion (physics §4), in closed form: the reference of the benchmarks on
//! unperturbed steady scenes.

use crate::model::{Coin, State, Steady};

/// The state at time `t` of the steady motion `steady` started from `start` (physics §4): θ and ω
/// constant, φ = φ₀ + φ̇t, ψ = ψ₀ + ψ̇t, the centre on its circle about C = p₀ + r(sin φ₀, cos φ₀),
/// r = aω_Z/φ̇: x = C_x − r sin φ, z = C_z − r cos φ (from ẋ = −aω_Z cos φ, ż = aω_Z sin φ at ω_X = 0); a
/// straight line x = x₀ − aω_Z cos φ₀ t, z = z₀ + aω_Z sin φ₀ t when φ̇ = 0.
///
/// ```
/// use coin_log::analyse::steady_path::steady_state_at;
/// use coin_log::model::{Coin, CoinParams, Steady, SteadyKind};
/// // Straight rolling at ω_Z = 2 from the origin, heading φ = 0: x = −2t (ẋ = −aω_Z).
/// let coin = Coin::new(CoinParams::unit_disk());
/// let steady = Steady::new(&coin, SteadyKind::Straight { omega_z: 2.0 }).unwrap();
/// let s = steady_state_at(&coin, &steady, &steady.state, 3.0);
/// assert!((s.x + 6.0).abs() < 1e-15 && s.z.abs() < 1e-15 && (s.psi - 6.0).abs() < 1e-15);
/// ```
#[must_use]
pub fn steady_state_at(coin: &Coin, steady: &Steady, start: &State, t: f64) -> State {
    let a = coin.params().radius();
    let (x, z) = if steady.phi_dot == 0.0 {
        let (s0, c0) = start.phi.sin_cos();
        (
            start.x - a * start.omega_z * c0 * t,
            start.z + a * start.omega_z * s0 * t,
        )
    } else {
        // x − x₀ = −r(sin φ − sin φ₀) = −2r cos(φ̄) sin(φ̇t/2), z − z₀ = 2r sin(φ̄) sin(φ̇t/2), φ̄ the mean
        // angle: no cancellation for small t.
        let r = a * start.omega_z / steady.phi_dot;
        let half = 0.5 * steady.phi_dot * t;
        let mean = start.phi + half;
        let chord = 2.0 * r * half.sin();
        (start.x - chord * mean.cos(), start.z + chord * mean.sin())
    };
    State {
        phi: start.phi + steady.phi_dot * t,
        psi: start.psi + steady.psi_dot * t,
        x,
        z,
        ..*start
    }
}

//! The stability limit of verdem's kick–drift–kick step for one linear spring–dashpot contact.
//!
//! With u = v_(n+1/2) the half-step velocity the dashpot sees, a contact of effective mass
//! m_eff, ω0² = kn/m_eff and c = γn/m_eff advances as x' = x + dt u,
//! u' = (1 − c dt) u − ω0² dt x'; its matrix has trace 2 − c dt − (ω0 dt)² and determinant
//! 1 − c dt, and both eigenvalues lie in the unit circle (Jury's test) iff
//! (ω0 dt)² + 2 c dt < 4, i.e. dt < 2(√(1 + ζ²) − ζ)/ω0 with ζ = c/(2ω0).

/// The largest stable time step (time units) of a contact of stiffness `kn` (force/length),
/// absolute damping `gamman` (mass/time) and effective mass `meff`.
pub fn max_dt(kn: f64, gamman: f64, meff: f64) -> f64 {
    let w0 = (kn / meff).sqrt();
    let zeta = gamman / (2.0 * meff * w0);
    2.0 * ((1.0 + zeta * zeta).sqrt() - zeta) / w0
}

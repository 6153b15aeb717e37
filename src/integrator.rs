//! Time integration and static equilibrium, written once for both belt
//! models: the pin chain [`Chain`](crate::Chain) and the bushing chain
//! [`BushingChain`](crate::bushing::BushingChain).
//!
//! * [`Chain::step`](crate::Chain::step): variable-step **BDF2** (second order, L-stable, no
//!   numerical damping worth the name at 1–2 ms; BDF1 adds enough to inflate
//!   Λ) on the equations of motion (index 3 for the pin chain), solved by
//!   simplified Newton: the Jacobian is refactored only when convergence
//!   slows. A step whose Newton iteration fails with a fresh Jacobian is
//!   rejected and retried at a quarter of the size; below `min_step_s` the
//!   run is a typed [`Error::Diverged`].
//! * [`Chain::solve_static`](crate::Chain::solve_static): the equilibrium the belt settles to, found by
//!   dynamic relaxation and then a proximal-point iteration (implicit Euler
//!   with the velocity reset each step, the time scale growing
//!   geometrically), each step solved by Newton with the tangent stiffness —
//!   a few dozen factorisations instead of seconds of simulated settling.
//!   Every proximal iterate first tries plain Newton on the static
//!   equations, which stops on the equilibrium nearest the shape. If that
//!   polish fails, it is run once more from the shape before the
//!   relaxation (see `solve_static` in this module).
//!
//! A model lends the algorithms its sizes, state arrays, residual, Newton
//! matrix and a few hooks (constraint multipliers, a prescribed joint)
//! through the crate-internal trait `Implicit`; the algorithms (`step_max`,
//! `solve_static`, `polish_static` in this module) know nothing else about
//! it, and the public `step`/`step_max`/`solve_static` of both chains call
//! them.

use crate::error::{invalid, Error, Result};
use crate::linalg::Dense;
use crate::params::Model;
use crate::real::Real;

/// Newton solves (restarted with a fresh Jacobian when one stops
/// contracting) of the static equations per proximal iterate.
const STATIC_NEWTON_ROUNDS: usize = 3;

/// Numerical settings of the integrator and the static solver.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Settings<T> {
    /// Nominal time step, s (BDF2 is accurate at 1–2 ms).
    pub step_s: T,
    /// Smallest step before the run is declared diverged, s.
    pub min_step_s: T,
    /// Newton iterations per attempt.
    pub newton_iterations: usize,
    /// Newton tolerance on positions, m.
    pub position_tol_m: T,
    /// Newton tolerance on angles, rad.
    pub angle_tol_rad: T,
    /// Largest proximal time scale of the static solver, s.
    pub static_tau_max_s: T,
    /// Outer iterations the static solver may spend.
    pub static_iterations: usize,
    /// Step of the dynamic relaxation that precedes the static polish, s.
    pub relax_step_s: T,
    /// Most steps of dynamic relaxation.
    pub relax_steps: usize,
    /// End the relaxation after this many steps from rest without any
    /// kinetic-energy peak while the belt barely moves (every joint under
    /// 1 mm/s): a start already near equilibrium, such as the end of a
    /// dynamic test, where the belt only creeps along a soft mode and
    /// would otherwise relax for all `relax_steps`. The Newton polish
    /// then settles it to the same tolerance. 0 (the default): never; the
    /// creep's extent then moves the settled state along the soft mode
    /// as far as `relax_steps` lets it, which a calibration's figures
    /// follow. The diagnosis's forward model sets 200.
    #[cfg_attr(feature = "serde", serde(default))]
    pub relax_creep_steps: usize,
}

impl<T: Real> Default for Settings<T> {
    fn default() -> Self {
        Settings {
            step_s: T::from_f64(2.0e-3),
            min_step_s: T::from_f64(1.0e-7),
            newton_iterations: 8,
            position_tol_m: T::from_f64(1.0e-9),
            angle_tol_rad: T::from_f64(1.0e-8),
            static_tau_max_s: T::from_f64(4.0),
            static_iterations: 400,
            relax_step_s: T::from_f64(5.0e-3),
            relax_steps: 3000,
            relax_creep_steps: 0,
        }
    }
}

impl<T: Real> Settings<T> {
    /// Check the settings.
    pub fn validate(&self) -> Result<()> {
        let pos = |x: T| x.is_finite() && x > T::ZERO;
        if !pos(self.step_s) {
            return Err(invalid("settings.step_s", "must be positive and finite"));
        }
        if !pos(self.min_step_s) || self.min_step_s > self.step_s {
            return Err(invalid(
                "settings.min_step_s",
                "must be positive and not above step_s",
            ));
        }
        if self.newton_iterations < 2 || self.newton_iterations > 50 {
            return Err(invalid(
                "settings.newton_iterations",
                "must be between 2 and 50",
            ));
        }
        if !pos(self.position_tol_m) || !pos(self.angle_tol_rad) || !pos(self.static_tau_max_s) {
            return Err(invalid(
                "settings tolerances",
                "must be positive and finite",
            ));
        }
        if !pos(self.relax_step_s)
            || self.relax_steps > 1_000_000
            || self.relax_creep_steps > 1_000_000
        {
            return Err(invalid(
                "settings.relax_step_s/relax_steps/relax_creep_steps",
                "step must be positive and finite, at most 1e6 steps",
            ));
        }
        if self.static_iterations == 0 || self.static_iterations > 100_000 {
            return Err(invalid(
                "settings.static_iterations",
                "must be between 1 and 100000",
            ));
        }
        Ok(())
    }
}

/// Solver counters, for benchmarks and diagnostics.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected (halved) steps.
    pub rejected: u64,
    /// Residual evaluations.
    pub residuals: u64,
    /// Jacobian factorisations.
    pub factorizations: u64,
}

/// How a Newton solve ended.
enum Newton {
    Converged { iterations: usize, rate: f64 },
    Failed,
}

/// The integrator's state of a model, borrowed all at once (the algorithms
/// read and write several arrays in one loop).
///
/// The unknowns `z` of a Newton solve are the model's coordinates (the first
/// [`Implicit::ndof`] entries, the ones `q`, `v` and `acc` hold) followed by
/// any algebraic unknowns (constraint multipliers) up to
/// [`Implicit::nsys`]. Velocities and accelerations are tied to the
/// coordinates by the implicit relation `v = αv·z + bv`, `a = αa·z + ba`.
pub(crate) struct State<'a, T, const D: usize> {
    /// Coordinates.
    pub q: &'a mut [T; D],
    /// Velocities.
    pub v: &'a mut [T; D],
    /// Accelerations.
    pub acc: &'a mut [T; D],
    /// Simulated time, s.
    pub time: &'a mut T,
    /// Coordinates one step back (BDF2 history).
    pub q_old: &'a mut [T; D],
    /// Velocities one step back.
    pub v_old: &'a mut [T; D],
    /// Size of the last accepted step, s.
    pub h_old: &'a mut T,
    /// `q_old`, `v_old` and `h_old` hold a step (else BDF1).
    pub history: &'a mut bool,
    /// Size of the next step to try, s.
    pub h_next: &'a mut T,
    /// `αv` of the implicit relation.
    pub alpha_v: &'a mut T,
    /// `αa` of the implicit relation.
    pub alpha_a: &'a mut T,
    /// `bv` of the implicit relation.
    pub bv: &'a mut [T; D],
    /// `ba` of the implicit relation.
    pub ba: &'a mut [T; D],
    /// Static equations (no friction or damping of the dynamics; the
    /// model holds its pinned coordinates).
    pub static_mode: &'a mut bool,
    /// The Newton matrix.
    pub jac: &'a mut Dense<T, D>,
    /// `(αa, αv)` the Newton matrix was assembled with.
    pub jac_alpha: &'a mut (T, T),
    /// Solver counters.
    pub stats: &'a mut Stats,
}

/// The [`Implicit`] methods that only read or lend fields, for a model that
/// holds them under the integrator's names (`settings`, `model`, `n`, `l`,
/// `m`, `roller_kg`, the state arrays, `jac`, `jac_alpha`, `stats`): expands
/// inside the `impl Implicit`.
macro_rules! implicit_fields {
    () => {
        fn settings(&self) -> &$crate::integrator::Settings<T> {
            &self.settings
        }
        fn model(&self) -> &$crate::params::Model<T> {
            &self.model
        }
        fn links(&self) -> usize {
            self.n
        }
        fn link_length_m(&self) -> T {
            self.l
        }
        fn moving_mass_kg(&self) -> T {
            self.m * T::from_usize(self.n) + self.roller_kg
        }
        fn q(&self) -> &[T; D] {
            &self.q
        }
        fn state(&mut self) -> $crate::integrator::State<'_, T, D> {
            $crate::integrator::State {
                q: &mut self.q,
                v: &mut self.v,
                acc: &mut self.acc,
                time: &mut self.time,
                q_old: &mut self.q_old,
                v_old: &mut self.v_old,
                h_old: &mut self.h_old,
                history: &mut self.history,
                h_next: &mut self.h_next,
                alpha_v: &mut self.alpha_v,
                alpha_a: &mut self.alpha_a,
                bv: &mut self.bv,
                ba: &mut self.ba,
                static_mode: &mut self.static_mode,
                jac: &mut self.jac,
                jac_alpha: &mut self.jac_alpha,
                stats: &mut self.stats,
            }
        }
    };
}
pub(crate) use implicit_fields;

/// A belt model the implicit integrator and the static solver can drive:
/// its sizes, state, residual and Newton matrix.
pub(crate) trait Implicit<T: Real, const D: usize> {
    /// What a failed static solve reports it was solving.
    const STATIC_WHAT: &'static str;

    /// Number of coordinates (held in `q`, `v`, `acc`).
    fn ndof(&self) -> usize;
    /// Size of the Newton system: coordinates plus algebraic unknowns.
    fn nsys(&self) -> usize;
    /// Coordinate `i` is a length (m) rather than an angle (rad).
    fn is_length_coord(&self, i: usize) -> bool;
    /// The numerical settings.
    fn settings(&self) -> &Settings<T>;
    /// The model.
    fn model(&self) -> &Model<T>;
    /// Number of links.
    fn links(&self) -> usize;
    /// Link length, m.
    fn link_length_m(&self) -> T;
    /// Mass of the belt and whatever it carries (the roller), kg.
    fn moving_mass_kg(&self) -> T;
    /// The stiffest spring whose force balance rounding limits, N/m (the
    /// contact laws; a model with stiffer joints says so).
    fn stiffest_spring_n_per_m(&self) -> f64 {
        let m = self.model();
        m.floor
            .stiffness_n_per_m
            .to_f64()
            .max(m.self_contact.stiffness_n_per_m.to_f64())
    }
    /// Coordinates, read only.
    fn q(&self) -> &[T; D];
    /// The integrator's state, borrowed mutably.
    fn state(&mut self) -> State<'_, T, D>;

    /// Residual of the equations at unknowns `z` (with the implicit relation
    /// of [`State`]) into `out[..nsys]`.
    fn residual(&mut self, z: &[T; D], out: &mut [T; D]);
    /// Assemble the Newton matrix at `z` (right after `residual(z)`, whose
    /// scratch it may use), factor it and count the factorisation.
    fn assemble_jacobian(&mut self, z: &[T; D]) -> Result<()>;
    /// Solve with the factored Newton matrix in place: `r` is a right-hand
    /// side on entry, the solution on exit.
    fn solve(&self, r: &mut [T; D]);

    /// Algebraic unknowns of the present state (constraint multipliers)
    /// into `z[ndof..nsys]`.
    fn load_algebraic(&self, _z: &mut [T; D]) {}
    /// Keep the algebraic unknowns of an accepted solution `z`.
    fn store_algebraic(&mut self, _z: &[T; D]) {}
    /// Put coordinates the model prescribes at time `t` (a driven joint)
    /// into a predicted `z`.
    fn prescribe(&self, _z: &mut [T; D], _t: T) {}
    /// Bring derived quantities (kinematics) up to date after `q` and `v`
    /// changed.
    fn update_kinematics(&mut self);
    /// Move the joint law's memory states on over the accepted step of
    /// `h` s (from `q_old` to `q`); nothing for a chain without them.
    fn accept_memory(&mut self, _h: T) {}
    /// Zero velocities and accelerations and forget the history.
    fn reset_motion(&mut self);
    /// Kinetic energy, J.
    fn kinetic_energy_j(&self) -> T;
    /// Largest speed of any joint, m/s.
    fn max_joint_speed_m_s(&self) -> T;
    /// No NaN/inf (or saturation in fixed point) in `q` and `v`.
    fn state_is_finite(&self) -> bool;
}

/// Weighted max-norm of a correction: 1 means "at the tolerance".
fn correction_norm<T: Real, const D: usize, C: Implicit<T, D>>(c: &C, dz: &[T; D]) -> f64 {
    let nd = c.ndof();
    let eps = T::epsilon().to_f64() * 64.0;
    let pt = c.settings().position_tol_m.to_f64().max(eps);
    let at = c.settings().angle_tol_rad.to_f64();
    let q = c.q();
    let mut worst = 0.0f64;
    for (i, d) in dz.iter().enumerate().take(nd) {
        let d = d.to_f64().abs();
        let tol = if c.is_length_coord(i) {
            pt
        } else {
            // f32 cannot resolve 1e-8 rad on angles of a few radians.
            at.max(eps * (1.0 + q[i].to_f64().abs()))
        };
        worst = worst.max(d / tol);
    }
    worst
}

/// Newton iteration from `z` (updated in place); `full` refactors the
/// Newton matrix every iteration.
fn newton<T: Real, const D: usize, C: Implicit<T, D>>(
    c: &mut C,
    z: &mut [T; D],
    full: bool,
) -> Newton {
    let ns = c.nsys();
    let mut r = [T::ZERO; D];
    let mut prev = f64::INFINITY;
    let mut rate = 0.0;
    for it in 0..c.settings().newton_iterations {
        c.residual(z, &mut r);
        if !r[..ns].iter().all(|x| x.is_finite()) {
            return Newton::Failed;
        }
        if full && it > 0 && c.assemble_jacobian(z).is_err() {
            return Newton::Failed;
        }
        for x in r.iter_mut().take(ns) {
            *x = -*x;
        }
        c.solve(&mut r);
        for i in 0..ns {
            z[i] += r[i];
        }
        let norm = correction_norm(c, &r);
        if !norm.is_finite() {
            return Newton::Failed;
        }
        if it > 0 {
            rate = norm / prev;
            if rate >= 0.9 {
                return Newton::Failed;
            }
        }
        // Converged when the correction (and the error it leaves,
        // estimated from the contraction rate) is below tolerance.
        let left = if it > 0 {
            norm * rate / (1.0 - rate)
        } else {
            norm
        };
        if norm <= 1.0 && left <= 1.0 {
            return Newton::Converged {
                iterations: it + 1,
                rate,
            };
        }
        prev = norm;
    }
    Newton::Failed
}

/// BDF coefficients for a step `h` after a step `h_old`.
fn set_bdf<T: Real, const D: usize, C: Implicit<T, D>>(c: &mut C, h: T) {
    let nd = c.ndof();
    let s = c.state();
    let (a0, a1, a2) = if *s.history {
        let w = h / *s.h_old;
        let one = T::ONE;
        let two = T::from_f64(2.0);
        (
            (one + two * w) / (h * (one + w)),
            -(one + w) / h,
            w * w / (h * (one + w)),
        )
    } else {
        (T::ONE / h, -T::ONE / h, T::ZERO)
    };
    *s.alpha_v = a0;
    *s.alpha_a = a0 * a0;
    for i in 0..nd {
        let bv = a1 * s.q[i] + a2 * s.q_old[i];
        s.bv[i] = bv;
        s.ba[i] = a0 * bv + a1 * s.v[i] + a2 * s.v_old[i];
    }
}

/// The Newton matrix is current for the present coefficients.
fn jacobian_current<T: Real, const D: usize, C: Implicit<T, D>>(c: &mut C) -> bool {
    let ns = c.nsys();
    let s = c.state();
    s.jac.is_factored()
        && s.jac.dim() == ns
        && s.jac_alpha.0 == *s.alpha_a
        && (*s.static_mode || s.jac_alpha.1 == *s.alpha_v)
}

/// Residual, then a fresh Newton matrix, at `z`.
fn refresh_jacobian<T: Real, const D: usize, C: Implicit<T, D>>(
    c: &mut C,
    z: &[T; D],
) -> Result<()> {
    let mut r = [T::ZERO; D];
    c.residual(z, &mut r);
    c.assemble_jacobian(z)
}

/// The typed error of a failed step.
fn diverged<T: Real, const D: usize, C: Implicit<T, D>>(c: &mut C, reason: &'static str) -> Error {
    Error::Diverged {
        time_s: c.state().time.to_f64(),
        reason,
    }
}

/// Advance `c` by one BDF2 step of at most `h_max` seconds (see the module
/// docs).
pub(crate) fn step_max<T: Real, const D: usize, C: Implicit<T, D>>(
    c: &mut C,
    h_max: T,
) -> Result<()> {
    if !h_max.is_finite() || h_max <= T::ZERO {
        return Err(Error::NonFinite { what: "step size" });
    }
    *c.state().static_mode = false;
    let nd = c.ndof();
    let settings = *c.settings();
    let mut h = c.state().h_next.min(h_max);
    for _attempt in 0..64 {
        set_bdf(c, h);
        // Predictor: Taylor extrapolation of q; previous multipliers.
        let mut z = [T::ZERO; D];
        let half = T::from_f64(0.5);
        let s = c.state();
        for i in 0..nd {
            z[i] = s.q[i] + h * s.v[i] + half * h * h * s.acc[i];
        }
        let t = *s.time + h;
        c.load_algebraic(&mut z);
        // A prescribed coordinate is exactly where it must be.
        c.prescribe(&mut z, t);
        let mut fresh = false;
        if !jacobian_current(c) {
            if refresh_jacobian(c, &z).is_err() {
                return Err(diverged(c, "singular Newton matrix"));
            }
            fresh = true;
        }
        match newton(c, &mut z, false) {
            Newton::Converged { iterations, rate } => {
                accept(c, &z, h);
                if iterations > 3 || rate > 0.25 {
                    c.state().jac.invalidate();
                }
                if !c.state_is_finite() {
                    return Err(diverged(c, "state became non-finite"));
                }
                *c.state().h_next = (h * T::from_f64(2.0)).min(settings.step_s);
                return Ok(());
            }
            Newton::Failed => {
                let s = c.state();
                s.jac.invalidate();
                if fresh {
                    s.stats.rejected += 1;
                    h *= T::from_f64(0.25);
                    if h < settings.min_step_s {
                        return Err(diverged(c, "Newton failed at the smallest step"));
                    }
                }
            }
        }
    }
    Err(diverged(c, "too many rejected attempts"))
}

/// The stepping loop of the scenarios (bench, rig, the estimator's
/// dynamics): `advance(c, t)` takes one step from the elapsed time `t`
/// until `elapsed(c)` reaches `end_s` (to within 1e-12 s).
///
/// Every accepted step but a final partial one advances by at least
/// `min_step_s` (a smaller step is a divergence), so the loop is given
/// `⌈end_s / min_step_s⌉ + 1` steps (at most 1e9); beyond that budget it
/// stops with [`Error::NotConverged`] naming `what`.
pub(crate) fn step_until<C, E, A>(
    c: &mut C,
    end_s: f64,
    min_step_s: f64,
    what: &'static str,
    elapsed: E,
    mut advance: A,
) -> Result<()>
where
    E: Fn(&C) -> f64,
    A: FnMut(&mut C, f64) -> Result<()>,
{
    let max_steps = libm::ceil(end_s / min_step_s).min(1.0e9) as u64 + 1;
    let mut steps = 0u64;
    while elapsed(c) < end_s - 1e-12 {
        if steps >= max_steps {
            return Err(Error::NotConverged {
                what,
                iterations: steps as usize,
            });
        }
        let t = elapsed(c);
        advance(c, t)?;
        steps += 1;
    }
    Ok(())
}

/// Take the converged step `z` of size `h`.
fn accept<T: Real, const D: usize, C: Implicit<T, D>>(c: &mut C, z: &[T; D], h: T) {
    let nd = c.ndof();
    let s = c.state();
    *s.q_old = *s.q;
    *s.v_old = *s.v;
    for i in 0..nd {
        s.q[i] = z[i];
        s.v[i] = *s.alpha_v * z[i] + s.bv[i];
        s.acc[i] = *s.alpha_a * z[i] + s.ba[i];
    }
    *s.h_old = h;
    *s.history = true;
    *s.time += h;
    s.stats.steps += 1;
    c.store_algebraic(z);
    c.update_kinematics();
    c.accept_memory(h);
}

/// Find the static equilibrium nearest the current shape (gravity, joint
/// stiffness, floor; no friction or damping) and leave `c` there at rest:
/// dynamic relaxation, then the Newton polish. Returns the number of
/// proximal iterations (of both polishes when the fallback ran).
///
/// **Fallback.** When the polish of the relaxed state fails (it runs out
/// of iterations or of time scale, or meets a singular Newton matrix), the
/// state as it was before the relaxation is restored and polished instead;
/// if that fails too, the first polish's error is returned. Wherever the
/// first polish converges the fallback never runs, so those results are
/// bit for bit what they were without it; the whole solve stays bounded
/// (two polishes of at most `static_iterations` each).
///
/// Why the relaxed state can be the worse start: the relaxation runs the
/// real dynamics, whose floor friction is regularised (it creeps below
/// its slip speed), for up to `relax_steps` steps. A belt loaded on top
/// (the roller of the dynamic test) is unstable in the frictionless static
/// equations along the soft mode in which the material circulates round
/// the loop — the roller's weight would roll it off the top, against the
/// links' own preference for a position — and where that mode is nearly
/// singular, the creep lets the belt roll a fraction of a link off the
/// symmetric shape the dynamic test settled to. From there the polish's
/// first Newton step jumps a third of a link along the soft mode and lifts
/// the belt off the floor (a singular matrix), and its proximal iteration
/// creeps along the mode without settling, while from the settled shape
/// itself Newton reaches the symmetric equilibrium (measured: truth
/// seed 78's belt at 44 links, its fitted table with Z3 × 1.05…1.3, see
/// `host-tests/tests/static_fallback.rs`).
pub(crate) fn solve_static<T: Real, const D: usize, C: Implicit<T, D>>(c: &mut C) -> Result<usize> {
    let nd = c.ndof();
    let mut before = [T::ZERO; D];
    before[..nd].copy_from_slice(&c.q()[..nd]);
    c.load_algebraic(&mut before);
    relax(c)?;
    let failed = match polish_static(c) {
        Err(e @ (Error::NotConverged { .. } | Error::Singular)) => e,
        settled => return settled,
    };
    restore(c, &before);
    match polish_static(c) {
        Ok(iterations) => Ok(outer_iterations(&failed) + iterations),
        Err(_) => Err(failed),
    }
}

/// The outer iterations a failed static polish spent.
fn outer_iterations(e: &Error) -> usize {
    match e {
        Error::NotConverged { iterations, .. } => *iterations,
        _ => 0,
    }
}

/// Put `c` back at the unknowns `z` (coordinates, then the algebraic
/// unknowns), at rest.
fn restore<T: Real, const D: usize, C: Implicit<T, D>>(c: &mut C, z: &[T; D]) {
    let nd = c.ndof();
    c.state().q[..nd].copy_from_slice(&z[..nd]);
    c.store_algebraic(z);
    c.reset_motion();
}

/// Dynamic relaxation: the real dynamics (gravity, contacts, joint
/// damping) with kinetic damping — all velocities are zeroed whenever the
/// kinetic energy passes a peak — until the belt barely moves. Brings any
/// start (a circle dropped on the floor, a still-oscillating belt) close to
/// the equilibrium for the Newton polish.
fn relax<T: Real, const D: usize, C: Implicit<T, D>>(c: &mut C) -> Result<()> {
    let t0 = *c.state().time;
    let settings = *c.settings();
    let h = settings.relax_step_s;
    c.reset_motion();
    let mut ke_prev = T::ZERO;
    let quiet = T::from_f64(1e-3);
    let mut resets = 0usize;
    for step in 1..=settings.relax_steps {
        step_max(c, h)?;
        let ke = c.kinetic_energy_j();
        if ke < ke_prev {
            c.reset_motion();
            resets += 1;
            ke_prev = T::ZERO;
            if resets > 3 && c.max_joint_speed_m_s() < quiet {
                break;
            }
        } else {
            ke_prev = ke;
            // No peak yet: every step so far has crept from rest.
            if resets == 0
                && settings.relax_creep_steps > 0
                && step >= settings.relax_creep_steps
                && c.max_joint_speed_m_s() < quiet
            {
                break;
            }
        }
        if resets > 3 && ke < T::from_f64(1e-9) {
            break;
        }
    }
    c.reset_motion();
    *c.state().time = t0;
    Ok(())
}

/// The static residual (without the proximal term) is at the noise level:
/// every generalised force below 1e-7 of the belt's weight (times a link
/// length for moments), every algebraic equation (a closure) below a
/// nanometre. Soft modes — the material circulating round the loop while
/// the shape stays put — carry no force and need no convergence of the
/// position.
///
/// With `rounding`, the tolerance also admits the rounding of the spring
/// forces (the stiffest spring times the resolution of the positions,
/// summed along the belt): f32 cannot balance forces better than about
/// 0.2 N; for f64 this term is 1e-9 N and changes nothing.
fn in_equilibrium<T: Real, const D: usize, C: Implicit<T, D>>(
    c: &mut C,
    z: &[T; D],
    rounding: bool,
) -> bool {
    let nd = c.ndof();
    let ns = c.nsys();
    let s = c.state();
    let (aa, ba) = (*s.alpha_a, *s.ba);
    *s.alpha_a = T::ZERO;
    *s.ba = [T::ZERO; D];
    let mut r = [T::ZERO; D];
    c.residual(z, &mut r);
    let s = c.state();
    *s.alpha_a = aa;
    *s.ba = ba;
    let l = c.link_length_m().to_f64();
    let weight = c.moving_mass_kg().to_f64() * c.model().gravity_m_s2.to_f64().max(1.0);
    let eps = T::epsilon().to_f64();
    let spring_rounding = if rounding {
        8.0 * eps * c.stiffest_spring_n_per_m() * l * c.links() as f64
    } else {
        0.0
    };
    let tol_f = (1e-7 * weight).max(eps * 1e3 * weight).max(spring_rounding);
    let tol_m = tol_f * l;
    let close = 1e-9 + eps * 10.0;
    (0..nd).all(|i| {
        let tol = if c.is_length_coord(i) { tol_f } else { tol_m };
        r[i].to_f64().abs() <= tol
    }) && r[nd..ns].iter().all(|x| x.to_f64().abs() <= close)
}

/// How far the present state (taken at rest) is from a static equilibrium:
/// the largest generalised force of the static equations over the weight
/// of the belt and what it carries (moments over weight times a link
/// length), and the largest algebraic residual (the closure, m).
///
/// Evaluates the residual once and restores everything it touches (the
/// implicit relation, the counters, the kinematics), so a run that asks
/// computes exactly what it would have without asking.
pub(crate) fn static_imbalance<T: Real, const D: usize, C: Implicit<T, D>>(
    c: &mut C,
) -> (f64, f64) {
    let nd = c.ndof();
    let ns = c.nsys();
    let mut z = [T::ZERO; D];
    z[..nd].copy_from_slice(&c.q()[..nd]);
    c.load_algebraic(&mut z);
    let s = c.state();
    let saved = (
        *s.static_mode,
        *s.alpha_v,
        *s.alpha_a,
        *s.bv,
        *s.ba,
        *s.stats,
    );
    *s.static_mode = true;
    *s.alpha_v = T::ZERO;
    *s.alpha_a = T::ZERO;
    *s.bv = [T::ZERO; D];
    *s.ba = [T::ZERO; D];
    let mut r = [T::ZERO; D];
    c.residual(&z, &mut r);
    let s = c.state();
    *s.static_mode = saved.0;
    *s.alpha_v = saved.1;
    *s.alpha_a = saved.2;
    *s.bv = saved.3;
    *s.ba = saved.4;
    *s.stats = saved.5;
    c.update_kinematics();
    let l = c.link_length_m().to_f64();
    let weight = c.moving_mass_kg().to_f64() * c.model().gravity_m_s2.to_f64().max(1.0);
    let mut force = 0.0f64;
    for (i, x) in r.iter().enumerate().take(nd) {
        let scale = if c.is_length_coord(i) {
            weight
        } else {
            weight * l
        };
        force = worse(force, x.to_f64().abs() / scale);
    }
    let closure = r[nd..ns]
        .iter()
        .fold(0.0f64, |m, x| worse(m, x.to_f64().abs()));
    (force, closure)
}

/// The larger of two magnitudes, NaN counting as infinite.
fn worse(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::INFINITY
    } else {
        a.max(b)
    }
}

/// The proximal relation of the static polish: `v = 0`,
/// `a = k·(z − anchor)`.
fn set_proximal<T: Real, const D: usize, C: Implicit<T, D>>(c: &mut C, k: T, anchor: &[T; D]) {
    let nd = c.ndof();
    let s = c.state();
    *s.alpha_v = T::ZERO;
    *s.alpha_a = k;
    for i in 0..nd {
        s.bv[i] = T::ZERO;
        s.ba[i] = -k * anchor[i];
    }
}

/// Plain Newton on the static equations (no proximal term) from `z`; on
/// success — converged, and in equilibrium to the precision of the number
/// type — `z` holds the equilibrium.
///
/// The discrete belt has nearby equilibria along the soft mode in which the
/// material circulates round the loop (A on top, a saddle of that mode; the
/// belt turned by half a link, a minimum). The proximal iteration alone
/// drifts off the saddle at a rate set by how symmetric the relaxed shape
/// happens to be (rounding), so the reported equilibrium depended on the
/// number type; Newton converges to the nearest one whatever its stability.
fn newton_static<T: Real, const D: usize, C: Implicit<T, D>>(c: &mut C, z: &mut [T; D]) -> bool {
    let nd = c.ndof();
    {
        let s = c.state();
        *s.alpha_v = T::ZERO;
        *s.alpha_a = T::ZERO;
        for i in 0..nd {
            s.bv[i] = T::ZERO;
            s.ba[i] = T::ZERO;
        }
    }
    let mut trial = *z;
    for _ in 0..STATIC_NEWTON_ROUNDS {
        if refresh_jacobian(c, &trial).is_err() {
            return false;
        }
        if let Newton::Converged { .. } = newton(c, &mut trial, true) {
            if in_equilibrium(c, &trial, true) {
                *z = trial;
                return true;
            }
            return false;
        }
    }
    false
}

/// Newton polish of the equilibrium nearest the present shape
/// (proximal-point iteration, plain Newton tried first), leaving `c` there
/// at rest. Returns the number of proximal iterations.
pub(crate) fn polish_static<T: Real, const D: usize, C: Implicit<T, D>>(
    c: &mut C,
) -> Result<usize> {
    let nd = c.ndof();
    let settings = *c.settings();
    let mut anchor = [T::ZERO; D];
    let mut z = [T::ZERO; D];
    {
        let s = c.state();
        *s.static_mode = true;
        s.jac.invalidate();
        anchor[..nd].copy_from_slice(&s.q[..nd]);
        z[..nd].copy_from_slice(&s.q[..nd]);
    }
    c.load_algebraic(&mut z);
    let tau_max = settings.static_tau_max_s;
    let mut tau = T::from_f64(0.2).min(tau_max);
    let result = (|| {
        for it in 0..settings.static_iterations {
            // The equilibrium nearest the current iterate, if plain Newton
            // reaches it: stops on the symmetric equilibrium instead of
            // letting the frictionless belt creep round the loop into the
            // neighbouring one (see `newton_static`).
            if newton_static(c, &mut z) {
                return Ok(it + 1);
            }
            let k = T::ONE / (tau * tau);
            set_proximal(c, k, &anchor);
            let mut trial = z;
            if refresh_jacobian(c, &trial).is_err() {
                tau *= T::from_f64(0.25);
                if tau < T::from_f64(1e-4) {
                    return Err(Error::Singular);
                }
                continue;
            }
            match newton(c, &mut trial, true) {
                Newton::Converged { .. } => {
                    let mut dz = [T::ZERO; D];
                    for i in 0..nd {
                        dz[i] = trial[i] - anchor[i];
                    }
                    let moved = correction_norm(c, &dz);
                    z = trial;
                    anchor[..nd].copy_from_slice(&z[..nd]);
                    if (moved <= 10.0 && tau >= tau_max) || in_equilibrium(c, &z, false) {
                        return Ok(it + 1);
                    }
                    tau = (tau * T::from_f64(2.0)).min(tau_max);
                }
                Newton::Failed => {
                    tau *= T::from_f64(0.25);
                    if tau < T::from_f64(1e-4) {
                        return Err(Error::NotConverged {
                            what: C::STATIC_WHAT,
                            iterations: it + 1,
                        });
                    }
                }
            }
        }
        Err(Error::NotConverged {
            what: C::STATIC_WHAT,
            iterations: settings.static_iterations,
        })
    })();
    {
        let s = c.state();
        *s.static_mode = false;
        s.q[..nd].copy_from_slice(&z[..nd]);
    }
    c.store_algebraic(&z);
    c.reset_motion();
    if !c.state_is_finite() {
        return Err(Error::Diverged {
            time_s: c.state().time.to_f64(),
            reason: "static solve produced a non-finite state",
        });
    }
    result
}

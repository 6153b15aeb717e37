//! The belt as a closed chain of rigid links: coordinates, kinematics and
//! the equations of motion (residual and Jacobian for the implicit
//! integrator in [`crate::integrator`]).
//!
//! # Coordinates
//!
//! Joint 0 is point A (the top of the ring in the bench tests). The links
//! run clockwise from it: link `k` goes from joint `k` to joint `k+1`, at the
//! absolute angle `θ_k`. The generalised coordinates are
//! `q = (x₀, y₀, θ₀ … θ_{N−1})` — the position of joint 0 and the link
//! angles — so the pins are exact by construction; closing the loop
//! (`Σ L/N·(cos θ_k, sin θ_k) = 0`) is two algebraic constraints with
//! multipliers `λ`.
//!
//! The joint angle at joint `k` is `ζ_k = θ_k − θ_{k−1}` and, at the closing
//! joint, `ζ₀ = θ₀ − θ_{N−1} − 2π` (the chain turns by −2π clockwise), so the
//! angles always sum to −2π, stay continuous while the belt runs round, and
//! need no wrapping.
//!
//! The residual is computed in O(N) (prefix sums of accelerations, suffix
//! sums of forces); the Jacobian is dense, assembled in O(N²) and factored in
//! O(N³) only when Newton stops converging quickly.

use crate::contact::{Contact, ContactKind, LinkPoint, Wheels};
use crate::error::{Error, Result};
use crate::linalg::Dense;
use crate::params::Model;
use crate::real::Real;

pub(crate) const X: usize = 0;
pub(crate) const Y: usize = 1;
pub(crate) const TH: usize = 2;

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
        }
    }
}

impl<T: Real> Settings<T> {
    /// Check the settings.
    pub fn validate(&self) -> Result<()> {
        let pos = |x: T| x.is_finite() && x > T::ZERO;
        if !pos(self.step_s) {
            return Err(crate::params::invalid(
                "settings.step_s",
                "must be positive and finite",
            ));
        }
        if !pos(self.min_step_s) || self.min_step_s > self.step_s {
            return Err(crate::params::invalid(
                "settings.min_step_s",
                "must be positive and not above step_s",
            ));
        }
        if self.newton_iterations < 2 || self.newton_iterations > 50 {
            return Err(crate::params::invalid(
                "settings.newton_iterations",
                "must be between 2 and 50",
            ));
        }
        if !pos(self.position_tol_m) || !pos(self.angle_tol_rad) || !pos(self.static_tau_max_s) {
            return Err(crate::params::invalid(
                "settings tolerances",
                "must be positive and finite",
            ));
        }
        if !pos(self.relax_step_s) || self.relax_steps > 1_000_000 {
            return Err(crate::params::invalid(
                "settings.relax_step_s/relax_steps",
                "step must be positive and finite, at most 1e6 steps",
            ));
        }
        if self.static_iterations == 0 || self.static_iterations > 100_000 {
            return Err(crate::params::invalid(
                "settings.static_iterations",
                "must be between 1 and 100000",
            ));
        }
        Ok(())
    }
}

/// A link chain with its state and the solver's workspace.
///
/// `D` is the capacity in unknowns: a chain of N links needs `D ≥ N + 4`
/// (coordinates plus the two closure multipliers). [`ReferenceChain`] holds
/// up to 128 links in `f64`.
///
/// The struct owns everything it needs (no heap): about `8·D²` bytes of
/// Jacobian for `f64` plus `~25·D` scalars.
pub struct Chain<T: Real, const D: usize> {
    pub(crate) model: Model<T>,
    pub(crate) settings: Settings<T>,
    pub(crate) n: usize,
    pub(crate) l: T,
    pub(crate) m: T,
    pub(crate) inertia: T,
    pub(crate) half_t: T,
    pub(crate) two_pi: T,
    /// Point mass attached at joint 0 (the roller of the dynamic test), kg.
    pub(crate) roller_kg: T,
    /// The rig's idler axle (an extra coordinate after the link angles),
    /// when the chain runs on the rig.
    pub(crate) idler: Option<IdlerAxle<T>>,
    /// Quasi-static marching (the estimator's travelling-belt statics): in
    /// static mode, when `march_inv_dt > 0`, each joint's rate is
    /// `(ζ − march_ref[j])·march_inv_dt`, so the joint law's damping acts
    /// between consecutive equilibria (implicit Euler without inertia);
    /// contacts stay frictionless and joint A's x is held.
    pub(crate) march_inv_dt: T,
    /// Joint angles of the previous equilibrium of a march, rad.
    pub(crate) march_ref: [T; D],
    /// Static solves hold joint A's y as well as its x (the estimator's
    /// march holds joint A on the drive wheel's rim, like a sprocket tooth).
    pub(crate) pin_y: bool,
    /// In dynamics, joint A follows this circle (a sprocket tooth of the
    /// drive carrying it round) instead of moving freely.
    pub(crate) track: Option<Track<T>>,

    // State.
    pub(crate) q: [T; D],
    pub(crate) v: [T; D],
    pub(crate) acc: [T; D],
    pub(crate) lam: [T; 2],
    pub(crate) time: T,

    // BDF history and the current implicit relation
    // v = alpha_v·q + bv, a = alpha_a·q + ba.
    pub(crate) q_old: [T; D],
    pub(crate) v_old: [T; D],
    pub(crate) h_old: T,
    pub(crate) history: bool,
    pub(crate) h_next: T,
    pub(crate) alpha_v: T,
    pub(crate) alpha_a: T,
    pub(crate) bv: [T; D],
    pub(crate) ba: [T; D],
    pub(crate) static_mode: bool,

    /// Kinematics of the last evaluated state (positions, velocities).
    pub(crate) kin: Kinematics<T, D>,
    pub(crate) qdd: [T; D],

    // Residual scratch.
    pub(crate) fx: [T; D],
    pub(crate) fy: [T; D],
    pub(crate) mom: [T; D],
    pub(crate) gmom: [T; D],
    pub(crate) sx: [T; D],
    pub(crate) sy: [T; D],
    pub(crate) kj: [T; D],
    pub(crate) cj: [T; D],

    pub(crate) jac: Dense<T, D>,
    pub(crate) jac_alpha: (T, T),
    pub(crate) stats: Stats,
}

/// The idler axle of the rig: a slider along x pulled by the tensioner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct IdlerAxle<T> {
    /// Mass moving with the axle, kg.
    pub mass_kg: T,
    /// Viscous damping of the slider, N·s/m.
    pub damping_n_s_per_m: T,
    /// Tensioner force pulling the axle away from the drive (+x), N.
    pub force_n: T,
}

/// Joint A carried clockwise round a circle about the origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Track<T> {
    /// Circle radius, m.
    pub radius_m: T,
    /// Polar angle at `t0_s`, rad.
    pub phi0_rad: T,
    /// Clockwise angular speed, rad/s.
    pub omega_rad_s: T,
    /// Reference time, s.
    pub t0_s: T,
}

/// Joint angle ζ at joint `j` of the coordinates `q` of an `n`-link chain
/// (`two_pi` = 2π in the chain's number type): `θ_j − θ_{j−1}`, and at the
/// closing joint `θ₀ − θ_{N−1} − 2π`.
pub(crate) fn joint_angle_in<T: Real, const D: usize>(
    q: &[T; D],
    j: usize,
    n: usize,
    two_pi: T,
) -> T {
    if j == 0 {
        q[TH] - q[TH + n - 1] - two_pi
    } else {
        q[TH + j] - q[TH + j - 1]
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

/// The reference build: `f64`, up to 128 links.
pub type ReferenceChain = Chain<f64, 132>;

impl<T: Real, const D: usize> Chain<T, D> {
    /// A chain for `model`, laid out as a circle of circumference L resting
    /// on the floor (the start of the static test).
    pub fn new(model: Model<T>, settings: Settings<T>) -> Result<Self> {
        model.validate()?;
        settings.validate()?;
        let n = model.belt.links;
        if n + 4 > D {
            return Err(Error::Capacity {
                what: "chain unknowns (links + 4)",
                requested: n + 4,
                capacity: D,
            });
        }
        let l = model.belt.link_length_m();
        let m = model.belt.link_mass_kg();
        let z = [T::ZERO; D];
        let (floor, self_contact) = (model.floor, model.self_contact);
        let half_t = model.belt.thickness_m / T::from_f64(2.0);
        let mut chain = Chain {
            n,
            l,
            m,
            inertia: m * l * l / T::from_f64(12.0),
            half_t,
            two_pi: T::from_f64(core::f64::consts::TAU),
            roller_kg: T::ZERO,
            idler: None,
            march_inv_dt: T::ZERO,
            march_ref: z,
            pin_y: false,
            track: None,
            model,
            settings,
            q: z,
            v: z,
            acc: z,
            lam: [T::ZERO; 2],
            time: T::ZERO,
            q_old: z,
            v_old: z,
            h_old: settings.step_s,
            history: false,
            h_next: settings.step_s,
            alpha_v: T::ZERO,
            alpha_a: T::ZERO,
            bv: z,
            ba: z,
            static_mode: false,
            kin: Kinematics::new(n, l, half_t, floor, self_contact),
            qdd: z,
            fx: z,
            fy: z,
            mom: z,
            gmom: z,
            sx: z,
            sy: z,
            kj: z,
            cj: z,
            jac: Dense::new(),
            jac_alpha: (T::ZERO, T::ZERO),
            stats: Stats::default(),
        };
        chain.set_circle_on_floor();
        Ok(chain)
    }

    /// Number of links.
    pub fn links(&self) -> usize {
        self.n
    }

    /// The model.
    pub fn model(&self) -> &Model<T> {
        &self.model
    }

    /// Simulated time, s.
    pub fn time_s(&self) -> T {
        self.time
    }

    /// Solver counters.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Number of generalised coordinates.
    pub(crate) fn ndof(&self) -> usize {
        self.n + 2 + usize::from(self.idler.is_some())
    }

    /// Index of the idler axle coordinate (valid on the rig).
    pub(crate) fn idler_index(&self) -> usize {
        TH + self.n
    }

    /// Joint A's x is held (static solves, the estimator's march, a
    /// prescribed track).
    pub(crate) fn x_pinned(&self) -> bool {
        self.static_mode || self.track.is_some()
    }

    /// Joint A's y is held too.
    pub(crate) fn y_pinned(&self) -> bool {
        (self.static_mode && self.pin_y) || self.track.is_some()
    }

    /// Where a prescribed track puts joint A at time `t`, m.
    pub(crate) fn track_position(&self, t: T) -> Option<(T, T)> {
        self.track.map(|k| {
            let phi = k.phi0_rad - k.omega_rad_s * (t - k.t0_s);
            let (s, c) = phi.sin_cos();
            (k.radius_m * c, k.radius_m * s)
        })
    }

    /// Coordinate `i` is a length (m) rather than an angle (rad).
    pub(crate) fn is_length_coord(&self, i: usize) -> bool {
        i < TH || i >= TH + self.n
    }

    /// Size of the Newton system (coordinates + multipliers).
    pub(crate) fn nsys(&self) -> usize {
        self.ndof() + 2
    }

    /// Attach (or, with 0, remove) the roller's point mass at joint A, kg.
    pub fn set_roller_mass(&mut self, kg: T) -> Result<()> {
        if !kg.is_finite() || kg < T::ZERO {
            return Err(crate::params::invalid(
                "roller_kg",
                "must be finite and not negative",
            ));
        }
        self.roller_kg = kg;
        self.jac.invalidate();
        Ok(())
    }

    /// Lay the chain out as a regular polygon of circumference L (a circle
    /// formed from the belt), at rest, its lowest outer point on the floor.
    pub fn set_circle_on_floor(&mut self) {
        let n = self.n;
        let nn = T::from_usize(n);
        let pi = T::from_f64(core::f64::consts::PI);
        let half = T::from_f64(0.5);
        // Circumradius of the polygon.
        let (sin_half, _) = (pi / nn).sin_cos();
        let r = self.l / (T::from_f64(2.0) * sin_half);
        self.q = [T::ZERO; D];
        self.q[X] = T::ZERO;
        self.q[Y] = r;
        for k in 0..n {
            let phi = pi * half - self.two_pi * T::from_usize(k) / nn;
            self.q[TH + k] = phi - pi * half - pi / nn;
        }
        // Lift so the lowest outer corner touches y = 0.
        self.kinematics_positions();
        self.q[Y] -= self.kin.lowest_outer_y();
        self.reset_motion();
    }

    /// Zero velocities and accelerations and forget the integrator history.
    pub fn reset_motion(&mut self) {
        self.v = [T::ZERO; D];
        self.acc = [T::ZERO; D];
        self.history = false;
        self.h_next = self.settings.step_s;
        self.jac.invalidate();
        self.kinematics_positions();
    }

    /// Set the simulated time, s.
    pub fn set_time(&mut self, t: T) {
        self.time = t;
    }

    /// Joint angle ζ at joint `j` (rad): zero straight, negative bent the way
    /// the belt wraps. The angles of all joints sum to −2π.
    pub fn joint_angle(&self, j: usize) -> T {
        joint_angle_in(&self.q, j, self.n, self.two_pi)
    }

    /// Position of joint `j` (m), after the last step.
    pub fn joint_position_m(&self, j: usize) -> (T, T) {
        let j = j.min(self.n);
        (self.kin.px[j], self.kin.py[j])
    }

    /// Point of the outer surface at joint `j` (half the thickness off the
    /// axis, along the bisector of the two links' normals), m.
    pub fn outer_point_at_joint_m(&self, j: usize) -> (T, T) {
        let n = self.n;
        let j = j % n;
        let prev = if j == 0 {
            self.q[TH + n - 1] + self.two_pi
        } else {
            self.q[TH + j - 1]
        };
        let phi = (prev + self.q[TH + j]) * T::from_f64(0.5);
        let (s, c) = phi.sin_cos();
        (
            self.kin.px[j] - self.half_t * s,
            self.kin.py[j] + self.half_t * c,
        )
    }

    /// Height of the outer surface at A (joint 0) above the floor, m.
    pub fn a_height_m(&self) -> T {
        self.outer_point_at_joint_m(0).1
    }

    /// Overall width of the outer surface, m.
    pub fn width_m(&self) -> T {
        self.kin.outer_width()
    }

    /// Vertical velocity of joint A, m/s.
    pub fn a_velocity_m_s(&self) -> T {
        self.v[Y]
    }

    /// Largest speed of any joint, m/s (for "has it settled" checks).
    pub fn max_joint_speed_m_s(&self) -> T {
        self.kin.max_point_speed()
    }

    /// Power the joints' damping dissipates at the present state, W (the
    /// bending loss: the joint law's moment beyond its elastic part, times
    /// the joint rate).
    pub fn joint_damping_power_w(&self) -> T {
        let n = self.n;
        let law = &self.model.joint;
        let mut p = T::ZERO;
        for j in 0..n {
            let prev = if j == 0 { n - 1 } else { j - 1 };
            let rate = self.v[TH + j] - self.v[TH + prev];
            p += law.damping_power_w(self.joint_angle(j), rate);
        }
        p
    }

    /// Kinetic energy of the belt and roller, J.
    pub fn kinetic_energy_j(&self) -> T {
        let half = T::from_f64(0.5);
        let mut e = half * self.roller_kg * (self.v[X] * self.v[X] + self.v[Y] * self.v[Y]);
        for k in 0..self.n {
            let w = self.v[TH + k];
            let (c, s) = (self.kin.c[k], self.kin.s[k]);
            let hl = self.l * half;
            let vx = self.kin.pvx[k] - hl * s * w;
            let vy = self.kin.pvy[k] + hl * c * w;
            e += half * self.m * (vx * vx + vy * vy) + half * self.inertia * w * w;
        }
        if let Some(ax) = self.idler {
            let v = self.v[self.idler_index()];
            e += half * ax.mass_kg * v * v;
        }
        e
    }

    /// Check the state for NaN/inf (or saturation in fixed point).
    pub(crate) fn state_is_finite(&self) -> bool {
        let nd = self.ndof();
        self.q[..nd].iter().all(|x| x.is_finite()) && self.v[..nd].iter().all(|x| x.is_finite())
    }

    /// Positions only: sin/cos and joint positions from `self.q`.
    pub(crate) fn kinematics_positions(&mut self) {
        let n = self.n;
        let mut x = self.q[X];
        let mut y = self.q[Y];
        for k in 0..n {
            let (s, c) = self.q[TH + k].sin_cos();
            self.kin.c[k] = c;
            self.kin.s[k] = s;
            self.kin.px[k] = x;
            self.kin.py[k] = y;
            self.kin.pvx[k] = T::ZERO;
            self.kin.pvy[k] = T::ZERO;
            x += self.l * c;
            y += self.l * s;
        }
        self.kin.px[n] = x;
        self.kin.py[n] = y;
        // Velocities from the stored state.
        let mut vx = self.v[X];
        let mut vy = self.v[Y];
        for k in 0..n {
            self.kin.pvx[k] = vx;
            self.kin.pvy[k] = vy;
            let w = self.v[TH + k];
            self.kin.rate[k] = w;
            vx -= self.l * self.kin.s[k] * w;
            vy += self.l * self.kin.c[k] * w;
        }
        self.kin.pvx[n] = vx;
        self.kin.pvy[n] = vy;
        if self.idler.is_some() {
            let i = self.idler_index();
            if let Some(w) = self.kin.wheels.as_mut() {
                w.idler_x = self.q[i];
                w.idler_vx = self.v[i];
            }
        }
    }

    /// Residual of the equations of motion at the unknowns `z = (q, λ)`,
    /// with `v = alpha_v·q + bv` and `a = alpha_a·q + ba`.
    pub(crate) fn residual(&mut self, z: &[T; D], out: &mut [T; D]) {
        self.stats.residuals += 1;
        let n = self.n;
        let nd = self.ndof();
        let l = self.l;
        let m = self.m;
        let half = T::from_f64(0.5);
        let hl = l * half;
        let g = self.model.gravity_m_s2;

        // Velocities and accelerations of the coordinates.
        let mut vel = [T::ZERO; D];
        for i in 0..nd {
            vel[i] = self.alpha_v * z[i] + self.bv[i];
            self.qdd[i] = self.alpha_a * z[i] + self.ba[i];
        }
        // Positions, velocities, accelerations of the joints (prefix sums)
        // and the effective (inertial minus gravity) force on each link.
        let (mut x, mut y) = (z[X], z[Y]);
        let (mut vx, mut vy) = (vel[X], vel[Y]);
        let (mut ax, mut ay) = (self.qdd[X], self.qdd[Y]);
        for k in 0..n {
            let th = z[TH + k];
            let w = vel[TH + k];
            let wd = self.qdd[TH + k];
            let (s, c) = th.sin_cos();
            self.kin.c[k] = c;
            self.kin.s[k] = s;
            self.kin.px[k] = x;
            self.kin.py[k] = y;
            self.kin.pvx[k] = vx;
            self.kin.pvy[k] = vy;
            self.kin.rate[k] = w;
            // d²/dt² of l·e_k = l·(e'_k·θ̈ − e_k·θ̇²), e' = (−s, c).
            let w2 = w * w;
            let tx = -s * wd - c * w2;
            let ty = c * wd - s * w2;
            let acx = ax + hl * tx;
            let acy = ay + hl * ty;
            let f_x = m * acx;
            let f_y = m * (acy + g);
            self.fx[k] = f_x;
            self.fy[k] = f_y;
            // Moment of the COM force about the link's start joint, and its
            // derivative with respect to θ_k.
            self.mom[k] = hl * (-s * f_x + c * f_y);
            self.gmom[k] = hl * (c * f_x + s * f_y);
            x += l * c;
            y += l * s;
            vx -= l * s * w;
            vy += l * c * w;
            ax += l * tx;
            ay += l * ty;
        }
        self.kin.px[n] = x;
        self.kin.py[n] = y;
        self.kin.pvx[n] = vx;
        self.kin.pvy[n] = vy;
        // Roller (point mass at joint 0: no moment about joint 0).
        if self.roller_kg > T::ZERO {
            self.fx[0] += self.roller_kg * self.qdd[X];
            self.fy[0] += self.roller_kg * (self.qdd[Y] + g);
        }
        // The idler axle.
        let idler = self.idler_index();
        if let Some(w) = self.kin.wheels.as_mut() {
            w.idler_x = z[idler];
            w.idler_vx = vel[idler];
        }
        let mut idler_fx = T::ZERO;
        // Contacts: external forces at material points.
        // Contacts see velocities only in real dynamics (a march holds
        // joint A instead of driving the belt by friction).
        let with_velocity = !self.static_mode;
        let mut cfx = [T::ZERO; D];
        let mut cfy = [T::ZERO; D];
        let mut cm = [T::ZERO; D];
        let mut cg = [T::ZERO; D];
        self.kin.for_each_contact(with_velocity, |ch, ct| {
            let mut apply = |p: LinkPoint<T>, fx: T, fy: T| {
                let k = p.link;
                let (c, s) = (ch.c[k], ch.s[k]);
                cfx[k] += fx;
                cfy[k] += fy;
                // (u e' − w e)·f and (u e + w e')·f
                cm[k] += p.u * (-s * fx + c * fy) - p.w * (c * fx + s * fy);
                cg[k] += p.u * (c * fx + s * fy) + p.w * (-s * fx + c * fy);
            };
            apply(ct.a, ct.force.0, ct.force.1);
            if let Some(b) = ct.b {
                apply(b, -ct.force.0, -ct.force.1);
            }
            if ct.kind == ContactKind::Idler {
                idler_fx += ct.force.0;
            }
        });
        for k in 0..n {
            self.fx[k] -= cfx[k];
            self.fy[k] -= cfy[k];
            self.mom[k] -= cm[k];
            self.gmom[k] -= cg[k];
        }
        // Joint moments.
        let law = &self.model.joint;
        let mut mz = [T::ZERO; D];
        for j in 0..n {
            let (zeta, zr) = if j == 0 {
                (
                    z[TH] - z[TH + n - 1] - self.two_pi,
                    vel[TH] - vel[TH + n - 1],
                )
            } else {
                (z[TH + j] - z[TH + j - 1], vel[TH + j] - vel[TH + j - 1])
            };
            let rate = if !self.static_mode {
                zr
            } else if self.march_inv_dt > T::ZERO {
                (zeta - self.march_ref[j]) * self.march_inv_dt
            } else {
                T::ZERO
            };
            let jm = law.moment(zeta, rate);
            mz[j] = jm.moment_nm;
            self.kj[j] = jm.stiffness;
            self.cj[j] = jm.damping;
        }
        // Generalised residual (suffix sums of link forces).
        let (lx, ly) = (z[nd], z[nd + 1]);
        let (mut sfx, mut sfy) = (T::ZERO, T::ZERO);
        for j in (0..n).rev() {
            let (c, s) = (self.kin.c[j], self.kin.s[j]);
            self.sx[j] = sfx;
            self.sy[j] = sfy;
            let next = if j + 1 == n { 0 } else { j + 1 };
            out[TH + j] = l * (-s * (sfx + lx) + c * (sfy + ly))
                + self.mom[j]
                + self.inertia * self.qdd[TH + j]
                - (mz[j] - mz[next]);
            sfx += self.fx[j];
            sfy += self.fy[j];
        }
        out[X] = sfx;
        out[Y] = sfy;
        if self.x_pinned() {
            out[X] = T::ZERO;
            if self.y_pinned() {
                out[Y] = T::ZERO;
            }
        }
        if let Some(ax) = self.idler {
            out[idler] = ax.mass_kg * self.qdd[idler] + ax.damping_n_s_per_m * vel[idler]
                - ax.force_n
                + idler_fx;
        }
        // Closure.
        out[nd] = self.kin.px[n] - z[X];
        out[nd + 1] = self.kin.py[n] - z[Y];
    }

    /// Assemble and factor the Newton matrix at `z` (call right after
    /// `residual(z)`, whose scratch it uses).
    pub(crate) fn assemble_jacobian(&mut self, z: &[T; D]) -> Result<()> {
        self.build_jacobian(z);
        self.stats.factorizations += 1;
        self.jac.factor()
    }

    /// Assemble the Newton matrix at `z` without factoring it.
    pub(crate) fn build_jacobian(&mut self, z: &[T; D]) {
        let n = self.n;
        let nd = self.ndof();
        let ns = self.nsys();
        let l = self.l;
        let m = self.m;
        let aa = self.alpha_a;
        let av = if self.static_mode {
            T::ZERO
        } else {
            self.alpha_v
        };
        self.jac.reset(ns);
        let third = T::from_f64(1.0 / 3.0);
        let half = T::from_f64(0.5);
        // Mass matrix times alpha_a. W_k = mass beyond link k + m/2.
        let m_tot = m * T::from_usize(n) + self.roller_kg;
        {
            let a = &mut self.jac.a;
            a[X][X] = aa * m_tot;
            a[Y][Y] = aa * m_tot;
            let l2 = l * l;
            let mut wa = [T::ZERO; D];
            let mut wb = [T::ZERO; D];
            for k in 0..n {
                let beyond = m * T::from_usize(n - 1 - k);
                let wk = beyond + m * half;
                let (c, s) = (self.kin.c[k], self.kin.s[k]);
                let mxk = -l * s * wk * aa;
                let myk = l * c * wk * aa;
                a[X][TH + k] = mxk;
                a[TH + k][X] = mxk;
                a[Y][TH + k] = myk;
                a[TH + k][Y] = myk;
                a[TH + k][TH + k] = aa * l2 * (beyond + m * third);
                wa[k] = aa * l2 * wk * c;
                wb[k] = aa * l2 * wk * s;
            }
            for j in 0..n {
                let (cj, sj) = (self.kin.c[j], self.kin.s[j]);
                for k in (j + 1)..n {
                    let v = cj * wa[k] + sj * wb[k];
                    a[TH + j][TH + k] = v;
                    a[TH + k][TH + j] = v;
                }
            }
            // Joint stiffness and damping: tridiagonal with the closing corner.
            for j in 0..n {
                let d = self.kj[j]
                    + if self.static_mode {
                        self.march_inv_dt * self.cj[j]
                    } else {
                        av * self.cj[j]
                    };
                let p = if j == 0 { n - 1 } else { j - 1 };
                a[TH + j][TH + j] += d;
                a[TH + p][TH + p] += d;
                a[TH + j][TH + p] -= d;
                a[TH + p][TH + j] -= d;
            }
            // Geometric stiffness (diagonal): forces held fixed while the
            // link turns.
            let (lx, ly) = (z[nd], z[nd + 1]);
            for j in 0..n {
                let (c, s) = (self.kin.c[j], self.kin.s[j]);
                a[TH + j][TH + j] -=
                    l * (c * (self.sx[j] + lx) + s * (self.sy[j] + ly)) + self.gmom[j];
            }
            // Closure constraints (symmetric).
            for j in 0..n {
                let (c, s) = (self.kin.c[j], self.kin.s[j]);
                a[TH + j][nd] = -l * s;
                a[nd][TH + j] = -l * s;
                a[TH + j][nd + 1] = l * c;
                a[nd + 1][TH + j] = l * c;
            }
        }
        if let Some(ax) = self.idler {
            let i = self.idler_index();
            self.jac.a[i][i] = aa * ax.mass_kg + av * ax.damping_n_s_per_m;
        }
        // Contacts: rank-one terms J_Pᵀ·k·J_P.
        let with_velocity = !self.static_mode;
        let mut g = [T::ZERO; D];
        let jac = &mut self.jac;
        self.kin.for_each_contact(with_velocity, |ch, ct| {
            let kn = ct.kn + av * ct.cn;
            ch.contact_rank_one(jac, &mut g, ct, ct.normal, kn);
            if ct.ct > T::ZERO {
                ch.contact_rank_one(jac, &mut g, ct, ct.tangent, av * ct.ct);
            }
        });
        if self.x_pinned() {
            let last = if self.y_pinned() { Y } else { X };
            for p in X..=last {
                for i in 0..ns {
                    self.jac.a[p][i] = T::ZERO;
                    self.jac.a[i][p] = T::ZERO;
                }
                self.jac.a[p][p] = T::ONE;
            }
        }
        self.jac_alpha = (self.alpha_a, av);
    }
}

/// Positions and velocities of the joints of the last evaluated state, and
/// what the contact laws need to know about the belt.
pub(crate) struct Kinematics<T, const D: usize> {
    pub n: usize,
    pub l: T,
    pub half_t: T,
    pub floor: crate::params::Floor<T>,
    pub self_contact: crate::params::SelfContact<T>,
    pub floor_enabled: bool,
    /// The rig's wheels, when the chain runs on the rig.
    pub wheels: Option<Wheels<T>>,
    /// cos θ_k, sin θ_k.
    pub c: [T; D],
    pub s: [T; D],
    /// Joint positions and velocities (n + 1 entries: the last closes the loop).
    pub px: [T; D],
    pub py: [T; D],
    pub pvx: [T; D],
    pub pvy: [T; D],
    /// θ̇_k.
    pub rate: [T; D],
}

impl<T: Real, const D: usize> Kinematics<T, D> {
    /// Kinematics of an `n`-link belt at the origin, at rest, with the
    /// floor enabled and no wheels.
    pub(crate) fn new(
        n: usize,
        l: T,
        half_t: T,
        floor: crate::params::Floor<T>,
        self_contact: crate::params::SelfContact<T>,
    ) -> Self {
        let z = [T::ZERO; D];
        Kinematics {
            n,
            l,
            half_t,
            floor,
            self_contact,
            floor_enabled: true,
            wheels: None,
            c: z,
            s: z,
            px: z,
            py: z,
            pvx: z,
            pvy: z,
            rate: z,
        }
    }

    /// The outer-surface corners of every link (both ends).
    fn outer_corners(&self) -> impl Iterator<Item = (T, T)> + '_ {
        (0..self.n).flat_map(move |k| {
            [T::ZERO, self.l].into_iter().map(move |u| {
                self.point_position(LinkPoint {
                    link: k,
                    u,
                    w: self.half_t,
                })
            })
        })
    }

    /// Lowest point of the outer surface (no lower than joint 0), m.
    pub(crate) fn lowest_outer_y(&self) -> T {
        self.outer_corners()
            .fold(self.py[0], |lowest, p| lowest.min(p.1))
    }

    /// Overall width of the outer surface, m.
    pub(crate) fn outer_width(&self) -> T {
        let (lo, hi) = self
            .outer_corners()
            .fold((self.px[0], self.px[0]), |(lo, hi), p| {
                (lo.min(p.0), hi.max(p.0))
            });
        hi - lo
    }

    /// Largest speed (|vx| + |vy|) of any link's start joint, m/s.
    pub(crate) fn max_point_speed(&self) -> T {
        (0..self.n).fold(T::ZERO, |best, k| {
            best.max(self.pvx[k].abs() + self.pvy[k].abs())
        })
    }

    /// Fill `g` (indices `lo..=hi`) with `J_Pᵀ·d` of a link point.
    pub(crate) fn point_row(
        &self,
        g: &mut [T; D],
        p: LinkPoint<T>,
        d: (T, T),
        sign: T,
    ) -> (usize, usize) {
        let k = p.link;
        g[X] += sign * d.0;
        g[Y] += sign * d.1;
        for j in 0..k {
            g[TH + j] += sign * self.l * (-self.s[j] * d.0 + self.c[j] * d.1);
        }
        let (c, s) = (self.c[k], self.s[k]);
        g[TH + k] += sign * (p.u * (-s * d.0 + c * d.1) - p.w * (c * d.0 + s * d.1));
        (0, TH + k)
    }

    pub(crate) fn contact_rank_one(
        &self,
        jac: &mut Dense<T, D>,
        g: &mut [T; D],
        ct: &Contact<T>,
        d: (T, T),
        coef: T,
    ) {
        if coef == T::ZERO {
            return;
        }
        let (_, mut hi) = self.point_row(g, ct.a, d, T::ONE);
        if let Some(b) = ct.b {
            let (_, hb) = self.point_row(g, b, d, -T::ONE);
            hi = hi.max(hb);
        }
        if ct.kind == ContactKind::Idler {
            // The idler's rim moves with its axle coordinate.
            let i = TH + self.n;
            g[i] -= d.0;
            hi = hi.max(i);
        }
        // Skip the leading zeros (self-contact cancels the common prefix).
        let mut lo = 0;
        while lo <= hi && g[lo] == T::ZERO {
            lo += 1;
        }
        for i in lo..=hi {
            let gi = coef * g[i];
            if gi != T::ZERO {
                let row = &mut jac.a[i];
                for (x, &gj) in row[lo..=hi].iter_mut().zip(&g[lo..=hi]) {
                    *x += gi * gj;
                }
            }
        }
        for x in g.iter_mut().take(hi + 1) {
            *x = T::ZERO;
        }
    }
}

//! The belt as a closed chain of pin-jointed rigid links: its state, the
//! equations of motion (residual and Newton matrix) and its place in the
//! implicit integrator ([`crate::integrator`]); the coordinate layout and
//! joint positions are in `kinematics`, the contact laws in `contact`.
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

use crate::contact::{Contact, ContactKind, Contacts};
use crate::error::{Error, Result};
use crate::integrator::{self, Implicit, Settings, Stats};
use crate::kinematics::{Kinematics, LinkPoint, Polygon};
// The coordinate layout and joint angle, re-exported for the rig and the
// estimator's builder.
pub(crate) use crate::kinematics::{joint_angle_in, TH, X, Y};
use crate::linalg::Dense;
use crate::memory::Memory;
use crate::params::{roller_mass_kg, Model};
use crate::real::Real;

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
    /// The ground of a running gear (an extra coordinate after the
    /// idler's: its height), when the chain runs on one with ground.
    pub(crate) ground: Option<GroundAxle<T>>,
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
    /// What the belt can touch (floor, itself, the rig's wheels).
    pub(crate) contacts: Contacts<T>,
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
    /// Coordinate velocities, the contacts' forces and moments per link
    /// and the joint moments of the last residual (kept here so a
    /// residual clears only the entries it uses, not `D` of each).
    pub(crate) vel: [T; D],
    pub(crate) cfx: [T; D],
    pub(crate) cfy: [T; D],
    pub(crate) cm: [T; D],
    pub(crate) cg: [T; D],
    pub(crate) mz: [T; D],

    pub(crate) jac: Dense<T, D>,
    pub(crate) jac_alpha: (T, T),
    pub(crate) stats: Stats,
    /// The state of the joint law's terms with a memory (Dahl friction,
    /// Payne softening), per joint.
    pub(crate) memory: Memory<T, D>,
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
    /// A fixed idler centre: the spring holding the axle there (`None`:
    /// the constant force alone).
    pub hold: Option<CentreHold<T>>,
}

/// A stiff, damped spring holding the idler's axle at a fixed centre (a
/// fixed-centre tensioner): its force is the belt's pull on the idler.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CentreHold<T> {
    /// Where the axle is held (its coordinate), m.
    pub centre_m: T,
    /// Stiffness, N/m.
    pub stiffness_n_per_m: T,
    /// Damping, N·s/m.
    pub damping_n_s_per_m: T,
}

impl<T: Real> CentreHold<T> {
    /// The spring's force pushing the axle outwards at coordinate `x` and
    /// speed `v`, N.
    pub fn force_n(&self, x: T, v: T) -> T {
        self.stiffness_n_per_m * (self.centre_m - x) - self.damping_n_s_per_m * v
    }
}

/// The ground under a running gear: a horizontal surface whose height is a
/// coordinate, pushed up against the belt by the robot's weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GroundAxle<T> {
    /// Mass moving with the ground (numerical), kg.
    pub mass_kg: T,
    /// Viscous damping of its motion, N·s/m.
    pub damping_n_s_per_m: T,
    /// Upward force: the robot's weight carried by this track, N.
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
            ground: None,
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
            kin: Kinematics::new(n, l, half_t),
            contacts: Contacts::new(floor, self_contact),
            qdd: z,
            fx: z,
            fy: z,
            mom: z,
            gmom: z,
            sx: z,
            sy: z,
            kj: z,
            cj: z,
            vel: z,
            cfx: z,
            cfy: z,
            cm: z,
            cg: z,
            mz: z,
            jac: Dense::new(),
            jac_alpha: (T::ZERO, T::ZERO),
            stats: Stats::default(),
            memory: Memory::new(),
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
        self.n + 2 + usize::from(self.idler.is_some()) + usize::from(self.ground.is_some())
    }

    /// Index of the ground's coordinate (valid on a running gear with
    /// ground: after the idler's).
    pub(crate) fn ground_index(&self) -> usize {
        TH + self.n + 1
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
        self.roller_kg = roller_mass_kg(kg)?;
        self.jac.invalidate();
        Ok(())
    }

    /// Lay the chain out as a regular polygon of circumference L (a circle
    /// formed from the belt), at rest, its lowest outer point on the floor.
    pub fn set_circle_on_floor(&mut self) {
        let polygon = Polygon::new(self.n, self.l, self.two_pi);
        self.q = [T::ZERO; D];
        self.q[X] = T::ZERO;
        self.q[Y] = polygon.radius_m;
        for k in 0..self.n {
            self.q[TH + k] = polygon.link_angle(k);
        }
        // Lift so the lowest outer corner touches y = 0.
        self.kinematics_positions();
        self.q[Y] -= self.kin.lowest_outer_y();
        self.reset_motion();
    }

    /// Set the belt temperature used by `thermal_softening`
    /// ([`crate::effects`]), °C. Without that effect the temperature has no
    /// influence and this does nothing.
    pub fn set_belt_temperature_c(&mut self, temp_c: T) -> Result<()> {
        if !temp_c.is_finite() {
            return Err(Error::NonFinite {
                what: "belt temperature",
            });
        }
        if let Some(th) = &mut self.model.joint.effects.thermal_softening {
            th.temp_c = temp_c;
        }
        Ok(())
    }

    /// Zero velocities and accelerations and forget the integrator history.
    pub fn reset_motion(&mut self) {
        self.v = [T::ZERO; D];
        self.acc = [T::ZERO; D];
        self.history = false;
        self.h_next = self.settings.step_s;
        self.jac.invalidate();
        self.kinematics_positions();
        let (q, n, two_pi) = (&self.q, self.n, self.two_pi);
        self.memory.reset(n, |j| joint_angle_in(q, j, n, two_pi));
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
            let zeta = self.joint_angle(j);
            p += law.damping_power_w(zeta, rate);
            if law.effects.any_memory_term() {
                p += self
                    .memory
                    .power_w(j, zeta, rate, &law.effects, |x| law.stiffness.eval(x));
            }
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
        if let Some(gr) = self.ground {
            let v = self.v[self.ground_index()];
            e += half * gr.mass_kg * v * v;
        }
        e
    }

    /// Potential energy of the present state, J: gravity on the links and
    /// the roller (zero at y = 0), the joints' elastic energy
    /// ([`JointLaw::elastic_energy_j`](crate::joint::JointLaw::elastic_energy_j))
    /// and the contact springs (floor, self-contact, the rig's wheels). The
    /// rig's tensioner and prescribed drive do work on the belt and are not
    /// included.
    pub fn potential_energy_j(&self) -> T {
        let half = T::from_f64(0.5);
        let g = self.model.gravity_m_s2;
        let hl = self.l * half;
        let mut e = self.roller_kg * g * self.q[Y];
        for k in 0..self.n {
            e += self.m * g * (self.kin.py[k] + hl * self.kin.s[k]);
            e += self.model.joint.elastic_energy_j(self.joint_angle(k));
        }
        e + self.contacts.spring_energy_j(&self.kin)
    }

    /// Kinetic plus potential energy, J ([`Chain::kinetic_energy_j`],
    /// [`Chain::potential_energy_j`]): without external work it can only
    /// fall (damping, friction and the integrator dissipate).
    pub fn mechanical_energy_j(&self) -> T {
        self.kinetic_energy_j() + self.potential_energy_j()
    }

    /// How far the loop is from closing, m: the distance from the end of the
    /// last link to joint A (the closure constraint, zero to the Newton
    /// tolerance after every step).
    pub fn closure_residual_m(&self) -> T {
        self.closure_residuals().0
    }

    /// [`closure_residual_m`](Self::closure_residual_m) and
    /// [`closure_rate_residual_m_s`](Self::closure_rate_residual_m_s)
    /// together, with one sine and cosine per link: `(m, m/s)`.
    pub fn closure_residuals(&self) -> (T, T) {
        let (mut dx, mut dy) = (T::ZERO, T::ZERO);
        let (mut vx, mut vy) = (T::ZERO, T::ZERO);
        for k in 0..self.n {
            let (s, c) = self.q[TH + k].sin_cos();
            let w = self.v[TH + k];
            dx += self.l * c;
            dy += self.l * s;
            vx -= self.l * s * w;
            vy += self.l * c * w;
        }
        ((dx * dx + dy * dy).sqrt(), (vx * vx + vy * vy).sqrt())
    }

    /// The closure constraint differentiated in time, m/s: the velocity of
    /// the end of the last link relative to joint A. The integrator holds
    /// the closure on positions only, so this drifts with the step size.
    pub fn closure_rate_residual_m_s(&self) -> T {
        self.closure_residuals().1
    }

    /// How far the present state, taken at rest, is from a static
    /// equilibrium: `(force, closure)`, the largest generalised force of
    /// the static equations over the weight of the belt and roller
    /// (moments over weight × link length), and the closure residual, m.
    /// After [`Chain::solve_static`] both are at the solver's tolerance
    /// (force ≤ 1e-7) unless the solve stopped on its step criterion.
    /// Changes nothing in the state or the counters.
    pub fn static_imbalance(&mut self) -> (f64, f64) {
        integrator::static_imbalance(self)
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
            if let Some(w) = self.contacts.wheels.as_mut() {
                w.idler_x = self.q[i];
                w.idler_vx = self.v[i];
            }
        }
        if self.ground.is_some() {
            let i = self.ground_index();
            if let Some(g) = self.contacts.ground.as_mut() {
                g.y = self.q[i];
                g.vy = self.v[i];
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
        let vel = &mut self.vel;
        for i in 0..nd {
            vel[i] = self.alpha_v * z[i] + self.bv[i];
            self.qdd[i] = self.alpha_a * z[i] + self.ba[i];
        }
        let vel = &self.vel;
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
        if let Some(w) = self.contacts.wheels.as_mut() {
            w.idler_x = z[idler];
            w.idler_vx = vel[idler];
        }
        let (idler_ux, idler_uy) = self
            .contacts
            .wheels
            .map_or((T::ONE, T::ZERO), |w| (w.idler_ux, w.idler_uy));
        let ground = self.ground_index();
        if self.ground.is_some() {
            if let Some(g) = self.contacts.ground.as_mut() {
                g.y = z[ground];
                g.vy = vel[ground];
            }
        }
        let mut idler_fx = T::ZERO;
        let mut ground_fy = T::ZERO;
        // Contacts: external forces at material points.
        // Contacts see velocities only in real dynamics (a march holds
        // joint A instead of driving the belt by friction).
        let with_velocity = !self.static_mode;
        let (cfx, cfy, cm, cg) = (
            &mut self.cfx[..n],
            &mut self.cfy[..n],
            &mut self.cm[..n],
            &mut self.cg[..n],
        );
        for a in [&mut *cfx, &mut *cfy, &mut *cm, &mut *cg] {
            a.fill(T::ZERO);
        }
        self.contacts
            .for_each_contact(&self.kin, with_velocity, |ch, ct| {
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
                    idler_fx += ct.force.0 * idler_ux + ct.force.1 * idler_uy;
                }
                if ct.kind == ContactKind::Ground {
                    ground_fy += ct.force.1;
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
        let mz = &mut self.mz;
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
            let mut jm = law.moment(zeta, rate);
            if !self.static_mode && law.effects.any_memory_term() {
                let travel = zeta - joint_angle_in(&self.q, j, n, self.two_pi);
                jm =
                    self.memory
                        .apply(j, zeta, travel, &law.effects, |x| law.stiffness.eval(x), jm);
            }
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
            if let Some(h) = ax.hold {
                out[idler] -= h.force_n(z[idler], vel[idler]);
            }
        }
        if let Some(gr) = self.ground {
            out[ground] = gr.mass_kg * self.qdd[ground] + gr.damping_n_s_per_m * vel[ground]
                - gr.force_n
                + ground_fy;
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
            if let Some(h) = ax.hold {
                self.jac.a[i][i] += h.stiffness_n_per_m + av * h.damping_n_s_per_m;
            }
        }
        if let Some(gr) = self.ground {
            let i = self.ground_index();
            self.jac.a[i][i] = aa * gr.mass_kg + av * gr.damping_n_s_per_m;
        }
        // Contacts: rank-one terms J_Pᵀ·k·J_P.
        let with_velocity = !self.static_mode;
        let mut g = [T::ZERO; D];
        let jac = &mut self.jac;
        let axis = self
            .contacts
            .wheels
            .map_or((T::ONE, T::ZERO), |w| (w.idler_ux, w.idler_uy));
        self.contacts
            .for_each_contact(&self.kin, with_velocity, |ch, ct| {
                let kn = ct.kn + av * ct.cn;
                contact_rank_one(ch, jac, &mut g, ct, ct.normal, kn, axis);
                if ct.ct > T::ZERO {
                    contact_rank_one(ch, jac, &mut g, ct, ct.tangent, av * ct.ct, axis);
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

impl<T: Real, const D: usize> Implicit<T, D> for Chain<T, D> {
    const STATIC_WHAT: &'static str = "static equilibrium";

    fn ndof(&self) -> usize {
        Chain::ndof(self)
    }
    fn nsys(&self) -> usize {
        Chain::nsys(self)
    }
    fn is_length_coord(&self, i: usize) -> bool {
        Chain::is_length_coord(self, i)
    }
    integrator::implicit_fields!();
    fn residual(&mut self, z: &[T; D], out: &mut [T; D]) {
        Chain::residual(self, z, out)
    }
    fn assemble_jacobian(&mut self, z: &[T; D]) -> Result<()> {
        Chain::assemble_jacobian(self, z)
    }
    fn solve(&self, r: &mut [T; D]) {
        let ns = Chain::nsys(self);
        self.jac.solve(&mut r[..ns]);
    }
    /// The two closure multipliers.
    fn load_algebraic(&self, z: &mut [T; D]) {
        let nd = Chain::ndof(self);
        z[nd] = self.lam[0];
        z[nd + 1] = self.lam[1];
    }
    fn store_algebraic(&mut self, z: &[T; D]) {
        let nd = Chain::ndof(self);
        self.lam = [z[nd], z[nd + 1]];
    }
    /// A prescribed track holds joint A exactly where it must be.
    fn prescribe(&self, z: &mut [T; D], t: T) {
        if let Some((x, y)) = self.track_position(t) {
            z[X] = x;
            z[Y] = y;
        }
    }
    fn update_kinematics(&mut self) {
        self.kinematics_positions();
    }
    fn accept_memory(&mut self, h: T) {
        if self.model.joint.effects.any_memory_term() {
            let (n, two_pi) = (self.n, self.two_pi);
            let (before, after) = (&self.q_old, &self.q);
            self.memory.accept(
                n,
                h,
                &self.model.joint.effects,
                |j| joint_angle_in(before, j, n, two_pi),
                |j| joint_angle_in(after, j, n, two_pi),
            );
        }
    }
    fn reset_motion(&mut self) {
        Chain::reset_motion(self)
    }
    fn kinetic_energy_j(&self) -> T {
        Chain::kinetic_energy_j(self)
    }
    fn max_joint_speed_m_s(&self) -> T {
        Chain::max_joint_speed_m_s(self)
    }
    fn state_is_finite(&self) -> bool {
        Chain::state_is_finite(self)
    }
}

impl<T: Real, const D: usize> Chain<T, D> {
    /// Advance by one nominal step (`settings.step_s`, or less after a
    /// rejection, growing back by at most a factor 2 per step).
    pub fn step(&mut self) -> Result<()> {
        self.step_max(self.settings.step_s)
    }

    /// Advance by one step of at most `h_max` seconds.
    pub fn step_max(&mut self, h_max: T) -> Result<()> {
        integrator::step_max(self, h_max)
    }

    /// Find the static equilibrium nearest the current shape (gravity,
    /// joint stiffness, floor; no friction or damping), and leave the chain
    /// there at rest. Returns the number of proximal iterations.
    pub fn solve_static(&mut self) -> Result<usize> {
        integrator::solve_static(self)
    }

    /// Newton polish of the equilibrium (proximal-point iteration), without
    /// the dynamic relaxation before it.
    pub(crate) fn polish_static(&mut self) -> Result<usize> {
        integrator::polish_static(self)
    }
}

/// Add the rank-one term `coef·gᵀg` of a contact to the Newton matrix,
/// `g = J_Pᵀ·d` (minus that of the reaction point), using `g` as scratch.
fn contact_rank_one<T: Real, const D: usize>(
    kin: &Kinematics<T, D>,
    jac: &mut Dense<T, D>,
    g: &mut [T; D],
    ct: &Contact<T>,
    d: (T, T),
    coef: T,
    axis: (T, T),
) {
    if coef == T::ZERO {
        return;
    }
    let (_, mut hi) = kin.point_row(g, ct.a, d, T::ONE);
    if let Some(b) = ct.b {
        let (_, hb) = kin.point_row(g, b, d, -T::ONE);
        hi = hi.max(hb);
    }
    if ct.kind == ContactKind::Idler {
        // The idler's rim moves with its axle coordinate.
        let i = TH + kin.n;
        g[i] -= d.0 * axis.0 + d.1 * axis.1;
        hi = hi.max(i);
    }
    if ct.kind == ContactKind::Ground {
        // The ground moves with its height coordinate.
        let i = TH + kin.n + 1;
        g[i] -= d.1;
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

#[cfg(test)]
mod jac_check {
    //! The analytic Newton matrix against central differences of the
    //! residual.
    //!
    //! The measure is the largest `|J_fd − J|` of a column relative to that
    //! column's largest entry. Central differences with `h = 1e-7` have a
    //! truncation error of order `h²` times the residual's third
    //! derivative, negligible here, and a rounding error of about
    //! `ε·|R|/h ≈ 2e-16 × 1e3 / 1e-7 ≈ 2e-6` in the worst rows (the largest
    //! residual entries, ~1e3 with `αa = 1e6`), against column maxima of
    //! order one or more: about 1e-6 relative. The bound 1e-5 leaves a
    //! margin of ten over that; a wrong term (a sign, a factor, a missing
    //! coupling) is an error of order one of its own size.
    //!
    //! Simplified Newton leaves two terms out on purpose: the change of the
    //! mass matrix with the link angles times the accelerations, and the
    //! centripetal terms (`θ̇²`). Both vanish where velocities and
    //! accelerations are zero, so the exact checks run at such states; a
    //! moving state is checked against a looser bound that shows the
    //! omission stays small (Newton still contracts fast).
    extern crate std;
    use super::Chain;
    use crate::*;

    const N: usize = 132;

    /// Largest column-relative deviation of the analytic matrix from
    /// central differences at `z` (in the static mode, x₀ is pinned: its
    /// row and column are replaced by the identity and left out here).
    fn fd_error(c: &mut Chain<f64, N>, z: [f64; N]) -> f64 {
        let ns = c.nsys();
        let h = 1e-7;
        let mut r0 = [0.0; N];
        c.residual(&z, &mut r0);
        c.build_jacobian(&z);
        let mut worst = 0.0f64;
        for j in 0..ns {
            let (mut zp, mut zm) = (z, z);
            zp[j] += h;
            zm[j] -= h;
            let (mut r1, mut r2) = ([0.0; N], [0.0; N]);
            c.residual(&zp, &mut r1);
            c.residual(&zm, &mut r2);
            let colmax = (0..ns).map(|i| c.jac.a[i][j].abs()).fold(0.0, f64::max);
            for i in 0..ns {
                if c.static_mode && (i == 0 || j == 0) {
                    continue;
                }
                let fd = (r1[i] - r2[i]) / (2.0 * h);
                worst = worst.max((fd - c.jac.a[i][j]).abs() / (colmax + 1e-12));
            }
        }
        worst
    }

    /// The implicit relation `v = αv·(z − zz) + dv`, `a = αa·(z − zz) + da`:
    /// at rest at `zz` (`dv = da = 0`) or moving (fixed offsets).
    fn relation(c: &mut Chain<f64, N>, av: f64, aa: f64, zz: &[f64; N], moving: bool) {
        let nd = c.ndof();
        c.alpha_v = av;
        c.alpha_a = aa;
        for i in 0..nd {
            let (dv, da) = if moving {
                (0.1 * ((i * 3) as f64).cos(), ((i * 5) as f64).cos())
            } else {
                (0.0, 0.0)
            };
            c.bv[i] = -av * zz[i] + dv;
            c.ba[i] = -aa * zz[i] + da;
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let model = params::Model::paper(params::Variant::E38, params::Method::I).unwrap();
        let mut c = std::boxed::Box::new(ReferenceChain::new(model, Settings::default()).unwrap());
        let nd = c.ndof();
        // A bent, lowered circle (floor contacts active), with multipliers.
        let mut zz = [0.0; N];
        zz[..nd].copy_from_slice(&c.q[..nd]);
        for i in 2..nd {
            zz[i] += 0.01 * ((i * 7) as f64).sin();
        }
        zz[1] -= 0.003;
        zz[nd] = 3.0;
        zz[nd + 1] = -2.0;
        let mut report = std::vec::Vec::new();

        // Statics: stiffness, geometric stiffness, contacts, closure.
        c.static_mode = true;
        relation(&mut c, 0.0, 0.0, &zz, false);
        report.push(("static", fd_error(&mut c, zz), 1e-5));
        // The static solver's proximal term, at the iterate.
        relation(&mut c, 0.0, 1.0 / 0.05f64.powi(2), &zz, false);
        report.push(("proximal", fd_error(&mut c, zz), 1e-5));
        // Dynamics at rest: mass matrix, joint and contact damping,
        // friction slopes.
        c.static_mode = false;
        relation(&mut c, 1000.0, 1e6, &zz, false);
        report.push(("dynamic at rest", fd_error(&mut c, zz), 1e-5));
        // Moving: the omitted inertial terms (measured 5e-2).
        relation(&mut c, 1000.0, 1e6, &zz, true);
        report.push(("dynamic moving", fd_error(&mut c, zz), 0.1));

        for (label, err, tol) in report {
            std::eprintln!("{label}: worst column-relative error {err:.2e} (bound {tol:.0e})");
            assert!(err < tol, "{label}: {err:e} is not below {tol:e}");
        }
    }

    /// Like [`fd_error`], over the rows and columns of the coordinates
    /// `only` (their couplings to everything).
    fn fd_error_at(c: &mut Chain<f64, N>, z: [f64; N], only: &[usize]) -> f64 {
        let ns = c.nsys();
        let h = 1e-7;
        let mut r0 = [0.0; N];
        c.residual(&z, &mut r0);
        c.build_jacobian(&z);
        let mut worst = 0.0f64;
        for j in 0..ns {
            let (mut zp, mut zm) = (z, z);
            zp[j] += h;
            zm[j] -= h;
            let (mut r1, mut r2) = ([0.0; N], [0.0; N]);
            c.residual(&zp, &mut r1);
            c.residual(&zm, &mut r2);
            let colmax = (0..ns).map(|i| c.jac.a[i][j].abs()).fold(0.0, f64::max);
            for i in 0..ns {
                if !(only.contains(&i) || only.contains(&j))
                    || (c.static_mode && (i == 0 || j == 0))
                {
                    continue;
                }
                let fd = (r1[i] - r2[i]) / (2.0 * h);
                worst = worst.max((fd - c.jac.a[i][j]).abs() / (colmax + 1e-12));
            }
        }
        worst
    }

    /// A settled rig's chain, its state bent slightly, with multipliers.
    fn bent(c: &mut Chain<f64, N>) -> [f64; N] {
        let nd = c.ndof();
        let mut zz = [0.0; N];
        zz[..nd].copy_from_slice(&c.q[..nd]);
        for (i, z) in zz.iter_mut().enumerate().take(c.n + 2).skip(2) {
            *z += 1e-4 * ((i * 7) as f64).sin();
        }
        zz[nd] = 3.0;
        zz[nd + 1] = -2.0;
        zz
    }

    /// On a running gear: the ground's height coordinate (its row and
    /// column) matches central differences like the chain's terms above.
    /// The wheels' contacts leave out the turning of the contact normal
    /// with the positions (a simplified-Newton choice of the rig: 5e-3 on
    /// the paper rig here, 1e-3 on its idler's couplings), so the tilted
    /// idler's couplings and the whole matrix are compared with the paper
    /// rig's, not with 1e-5.
    #[test]
    fn jacobian_matches_finite_differences_on_a_running_gear() {
        // Two rigs of 132 unknowns: more stack than a test thread has in a
        // debug build.
        std::thread::Builder::new()
            .stack_size(256 << 20)
            .spawn(gear_jacobian)
            .unwrap()
            .join()
            .unwrap();
    }

    fn gear_jacobian() {
        use crate::gear::{Ground, RunningGear, Tensioner, Wheel, WheelRole};
        use crate::rig::{Rig, RigConfig};
        let model = params::Model::paper(params::Variant::E38, params::Method::I).unwrap();
        let mut g = RunningGear::new(Tensioner::Force { force_n: 400.0 });
        for (role, x_m, y_m, diameter_m) in [
            (WheelRole::Drive, 0.0, 0.0, 0.3),
            (WheelRole::Idler, 0.75, 0.06, 0.26),
            (WheelRole::Road, 0.25, -0.12, 0.15),
            (WheelRole::Road, 0.5, -0.12, 0.15),
        ] {
            g.push(Wheel {
                role,
                x_m,
                y_m,
                diameter_m,
            })
            .unwrap();
        }
        g.ground = Some(Ground { load_kg: 20.0 });
        let mut rig: std::boxed::Box<Rig<f64, N>> =
            std::boxed::Box::new(Rig::from_gear(model.clone(), &g, Settings::default()).unwrap());
        let f = rig.ground_force_n();
        assert!(
            (f / (20.0 * 9.81) - 1.0).abs() < 1e-3,
            "ground carries {f} N"
        );
        let fixed_at = (rig.idler_position_m(), 400.0);
        let model_fixed = model.clone();
        let c = rig.chain_mut();
        assert_eq!(c.ndof(), c.n + 4);
        let zz = bent(c);
        let (idler, ground) = (c.idler_index(), c.ground_index());
        let mut report = std::vec::Vec::new();
        c.static_mode = true;
        relation(c, 0.0, 0.0, &zz, false);
        report.push(("gear static: ground", fd_error_at(c, zz, &[ground]), 1e-5));
        let gear_idler_static = fd_error_at(c, zz, &[idler]);
        let whole_gear = fd_error(c, zz);
        c.static_mode = false;
        relation(c, 1000.0, 1e6, &zz, false);
        report.push((
            "gear dynamic at rest: ground",
            fd_error_at(c, zz, &[ground]),
            1e-5,
        ));
        let mut paper: std::boxed::Box<Rig<f64, N>> = std::boxed::Box::new(
            Rig::new(model, RigConfig::default(), Settings::default()).unwrap(),
        );
        let c = paper.chain_mut();
        let z2 = bent(c);
        c.static_mode = true;
        relation(c, 0.0, 0.0, &z2, false);
        let paper_idler = fd_error_at(c, z2, &[c.idler_index()]);
        let whole_paper = fd_error(c, z2);
        report.push((
            "gear static: tilted idler axle (vs the rig's idler)",
            gear_idler_static,
            2.0 * paper_idler.max(1e-5),
        ));
        report.push((
            "gear static, whole matrix (vs the rig's)",
            whole_gear,
            whole_paper.max(1e-5),
        ));
        // The same gear with the idler's centre fixed where the force left
        // it: the holding spring's row and column (stiffness and damping
        // exact; the contact couplings as the force tensioner's).
        let d = fixed_at.0;
        g.tensioner = Tensioner::FixedCentre;
        let (ux, uy) = (
            0.75 / libm::hypot(0.75, 0.06),
            0.06 / libm::hypot(0.75, 0.06),
        );
        g.wheels[1].x_m = d * ux;
        g.wheels[1].y_m = d * uy;
        let mut fixed: std::boxed::Box<Rig<f64, N>> =
            std::boxed::Box::new(Rig::from_gear(model_fixed, &g, Settings::default()).unwrap());
        let pull = fixed.idler_force_n();
        assert!(
            (pull / fixed_at.1 - 1.0).abs() < 0.05,
            "fixed centre: {pull} N"
        );
        let c = fixed.chain_mut();
        let zz = bent(c);
        let idler = c.idler_index();
        c.static_mode = true;
        relation(c, 0.0, 0.0, &zz, false);
        report.push((
            "fixed centre static: idler axle (vs the force tensioner's)",
            fd_error_at(c, zz, &[idler]),
            2.0 * gear_idler_static.max(1e-5),
        ));
        c.static_mode = false;
        relation(c, 1000.0, 1e6, &zz, false);
        report.push((
            "fixed centre dynamic: idler axle (vs the force tensioner's static)",
            fd_error_at(c, zz, &[idler]),
            2.0 * gear_idler_static.max(1e-5),
        ));
        for (label, err, tol) in report {
            std::eprintln!("{label}: worst column-relative error {err:.2e} (bound {tol:.1e})");
            assert!(err < tol, "{label}: {err:e} is not below {tol:e}");
        }
    }
}

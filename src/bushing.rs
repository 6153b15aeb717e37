//! The paper's literal joint (eqs. 1–3) as an option of the reference build:
//! consecutive links joined by a stiff planar **bushing** instead of an
//! exact pin.
//!
//! The bushing between the end point `P` of link `k−1` and the start point
//! `Q` of link `k` is a translational spring-damper plus the bending torque
//! of the [`JointLaw`](crate::joint::JointLaw):
//!
//! ```text
//! F = kx·(x_Q − x_P) + cx·(ẋ_Q − ẋ_P)   (on P; −F on Q), likewise in y
//! Mz = −f(ζ) − cz·ζ̇                     (as in the pin model)
//! ```
//!
//! with `kx = ky = 100 000 N/mm` (1e8 N/m) and `cx = cy = 1000 N·s/mm`
//! (1e6 N·s/m) ([`Bushing::paper`]). The paper prints eqs. 2–3 as
//! `k·(x₂−x₁) − c·(ẋ₂−ẋ₁)`, the same mixed sign convention as its eq. 1
//! (`kz·ζ − cz·ζ̇`); read literally the damper would feed energy in, so, as
//! for `Mz`, the law here is the restoring, dissipative one. With
//! `kx = ky` and `cx = cy` the bushing is isotropic, so whether its axes are
//! the joint's or the world's does not matter.
//!
//! # Coordinates and solver
//!
//! Maximal coordinates: link `k` has the position of its centre and its
//! angle, `(x_k, y_k, θ_k)`, so there are `3N` unknowns and no constraints.
//! Bushing `j` joins the end of link `j−1` to the start of link `j` (bushing
//! 0, at A, closes the loop: the end of link `N−1` to the start of link 0).
//! Joint angles are `ζ_j = θ_j − θ_{j−1}` and `ζ₀ = θ₀ − θ_{N−1} − 2π`,
//! exactly as in [`Chain`]. The roller of the dynamic test is
//! a point mass at the start of link 0.
//!
//! The bushing is far stiffer than anything else (its time constant
//! `m/c ≈ 2e-7 s` limits an explicit scheme to steps of about 2e-8 s), so
//! only an implicit scheme works. The chain implements the integrator's
//! model interface, so it is integrated and settled by the very code of the
//! pin model (see [`crate::integrator`]): variable-step BDF2 with simplified
//! Newton, dynamic relaxation and the proximal-point Newton polish. The
//! Newton matrix is stored dense (`3N × 3N`) but is
//! block-cyclic-tridiagonal (bushings and joint moments) apart from the
//! self-contact couplings: with the links numbered in folded order (0, N−1,
//! 1, N−2, …) it is a band of half-width 8, so the
//! LU (which skips zero multipliers) and the triangular solves (which skip
//! each row's zeros) cost O(N²) rather than O(N³). Rotational unknowns are
//! scaled by the link length and moment rows by its inverse, so every
//! unknown is a length and every row a force.
//!
//! The joints stretch by micrometres ([`BushingChain::max_stretch_m`]).
//! The bench figures agree with the pin model to a few thousandths of a
//! percent (`host-tests/tests/bushing.rs`); from the pin model's shape
//! ([`BushingChain::set_shape_from_pins`]) it finds the pin model's own
//! equilibrium to about 0.001 mm. It costs several times the pin model.
//!
//! ```
//! use trackbelt::{bench, bushing::{Bushing, BushingChain}, params::{Method, Model, Variant}, Settings};
//! let model = Model::paper(Variant::E38, Method::I)?;
//! // 38 links: 114 unknowns (the reference alias holds 128 links but is
//! // large: keep it on the heap).
//! let mut chain = BushingChain::<f64, 114>::new(model, Bushing::paper(), Settings::default())?;
//! let fig = bench::static_test(&mut chain)?;
//! assert!((fig.hs_mm - 324.0).abs() < 0.06 * 324.0);
//! assert!(chain.max_stretch_m() < 1e-5);
//! # Ok::<(), trackbelt::Error>(())
//! ```

use crate::chain::Chain;
use crate::contact::Contacts;
use crate::error::{invalid, Error, Result};
use crate::integrator::{self, Implicit, Settings, Stats};
use crate::kinematics::{Kinematics, LinkPoint, Polygon, TH};
use crate::linalg::{Band, Dense};
use crate::params::{roller_mass_kg, Model};
use crate::real::Real;

/// Translational law of the bushing (eqs. 2–3 of the paper).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bushing<T> {
    /// Stiffness `kx = ky`, N/m.
    pub stiffness_n_per_m: T,
    /// Damping `cx = cy`, N·s/m.
    pub damping_n_s_per_m: T,
}

impl<T: Real> Bushing<T> {
    /// The paper's values: 100 000 N/mm and 1000 N·s/mm.
    ///
    /// ```
    /// let b = trackbelt::bushing::Bushing::<f64>::paper();
    /// assert_eq!(b.stiffness_n_per_m, 1.0e8);
    /// assert_eq!(b.damping_n_s_per_m, 1.0e6);
    /// ```
    pub fn paper() -> Self {
        Bushing {
            stiffness_n_per_m: T::from_f64(1.0e8),
            damping_n_s_per_m: T::from_f64(1.0e6),
        }
    }

    /// Check the law.
    pub fn validate(&self) -> Result<()> {
        if !(self.stiffness_n_per_m.is_finite() && self.stiffness_n_per_m > T::ZERO) {
            return Err(invalid(
                "bushing.stiffness_n_per_m",
                "must be positive and finite",
            ));
        }
        if !(self.damping_n_s_per_m.is_finite() && self.damping_n_s_per_m >= T::ZERO) {
            return Err(invalid(
                "bushing.damping_n_s_per_m",
                "must be finite and not negative",
            ));
        }
        Ok(())
    }
}

/// The reference build of the bushing chain: `f64`, up to 128 links
/// (384 unknowns; about 1.3 MB, so keep it on the heap or on a large
/// stack).
pub type ReferenceBushingChain = BushingChain<f64, 384>;

/// Unknowns per link.
const PER: usize = 3;

/// A closed chain of rigid links joined by bushings, with its state and the
/// solver's workspace.
///
/// `D` is the capacity in unknowns: a chain of N links needs `D ≥ 3N`.
/// The Newton matrix takes `8·D²` bytes for `f64`.
pub struct BushingChain<T: Real, const D: usize> {
    model: Model<T>,
    bushing: Bushing<T>,
    pub(crate) settings: Settings<T>,
    n: usize,
    l: T,
    m: T,
    inertia: T,
    half_t: T,
    two_pi: T,
    roller_kg: T,

    // State: (x, y, θ) of every link's centre; `q[3k + 2]` is θ_k.
    q: [T; D],
    v: [T; D],
    acc: [T; D],
    time: T,

    // BDF history and the implicit relation v = αv·q + bv, a = αa·q + ba.
    q_old: [T; D],
    v_old: [T; D],
    h_old: T,
    history: bool,
    h_next: T,
    alpha_v: T,
    alpha_a: T,
    bv: [T; D],
    ba: [T; D],
    static_mode: bool,

    /// Link start points and their velocities (for the contact laws).
    kin: Kinematics<T, D>,
    /// What the belt can touch (floor, itself).
    contacts: Contacts<T>,
    /// Joint law tangents of the last residual.
    kj: [T; D],
    cj: [T; D],

    jac: Dense<T, D>,
    jac_alpha: (T, T),
    stats: Stats,
    /// The Newton matrix's banded mode: the links in folded order 0, N−1,
    /// 1, N−2, … (the loop becomes a band) and the extents of the factors'
    /// rows (the triangular solves skip the zeros outside).
    band: Band<D>,
}

/// A point of a link relative to its centre: `a` along the axis, `w` along
/// the outward normal.
#[derive(Clone, Copy)]
struct Arm<T> {
    link: usize,
    a: T,
    w: T,
}

/// Sparse gradient of a scalar (a force component along a direction) with
/// respect to the unknowns: at most two links, three entries each.
struct Grad<T> {
    idx: [usize; 6],
    val: [T; 6],
    len: usize,
}

impl<T: Real> Grad<T> {
    fn new() -> Self {
        Grad {
            idx: [0; 6],
            val: [T::ZERO; 6],
            len: 0,
        }
    }
    fn push(&mut self, i: usize, v: T) {
        if self.len < 6 {
            self.idx[self.len] = i;
            self.val[self.len] = v;
            self.len += 1;
        }
    }
}

impl<T: Real, const D: usize> BushingChain<T, D> {
    /// A bushing chain for `model`, laid out as a circle of circumference L
    /// resting on the floor (the start of the static test), the bushings
    /// unstretched.
    pub fn new(model: Model<T>, bushing: Bushing<T>, settings: Settings<T>) -> Result<Self> {
        model.validate()?;
        bushing.validate()?;
        settings.validate()?;
        if model.joint.effects.any_memory_term() {
            return Err(Error::InvalidParameter {
                field: "effects.dahl_friction / effects.payne_softening",
                reason: "laws with a memory run only in the pin chain (`Chain`); switch them off or use the pin joint",
            });
        }
        let n = model.belt.links;
        if n * PER > D || n + 1 > D || D > u16::MAX as usize {
            return Err(Error::Capacity {
                what: "bushing chain unknowns (3 per link)",
                requested: n * PER,
                capacity: D,
            });
        }
        let l = model.belt.link_length_m();
        let m = model.belt.link_mass_kg();
        let z = [T::ZERO; D];
        let half_t = model.belt.thickness_m / T::from_f64(2.0);
        let (floor, self_contact) = (model.floor, model.self_contact);
        let mut chain = BushingChain {
            n,
            l,
            m,
            inertia: m * l * l / T::from_f64(12.0),
            half_t,
            two_pi: T::from_f64(core::f64::consts::TAU),
            roller_kg: T::ZERO,
            model,
            bushing,
            settings,
            q: z,
            v: z,
            acc: z,
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
            kj: z,
            cj: z,
            jac: Dense::new(),
            jac_alpha: (T::ZERO, T::ZERO),
            stats: Stats::default(),
            band: Band::new(folded_order(n)),
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

    /// The bushing law.
    pub fn bushing(&self) -> &Bushing<T> {
        &self.bushing
    }

    /// The numerical settings.
    pub fn settings(&self) -> &Settings<T> {
        &self.settings
    }

    /// Simulated time, s.
    pub fn time_s(&self) -> T {
        self.time
    }

    /// Set the simulated time, s.
    pub fn set_time(&mut self, t: T) {
        self.time = t;
    }

    /// Solver counters.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    fn nsys(&self) -> usize {
        self.n * PER
    }

    /// Attach (or, with 0, remove) the roller's point mass at A (the start
    /// of link 0), kg.
    pub fn set_roller_mass(&mut self, kg: T) -> Result<()> {
        self.roller_kg = roller_mass_kg(kg)?;
        self.jac.invalidate();
        Ok(())
    }

    /// Lay the chain out as a regular polygon of circumference L, at rest,
    /// bushings unstretched, its lowest outer point on the floor.
    pub fn set_circle_on_floor(&mut self) {
        let n = self.n;
        let nn = T::from_usize(n);
        let pi = T::from_f64(core::f64::consts::PI);
        let half = T::from_f64(0.5);
        let polygon = Polygon::new(n, self.l, self.two_pi);
        self.q = [T::ZERO; D];
        // Joint 0 at (0, r); link k runs clockwise from joint k.
        let (mut x, mut y) = (T::ZERO, polygon.radius_m);
        for k in 0..n {
            // `Polygon::link_angle` rounded another way (kept: it moves the
            // start, and so this chain's figures, by a few ulps).
            let th = -self.two_pi * T::from_usize(k) / nn - pi / nn;
            let (s, c) = th.sin_cos();
            let b = PER * k;
            self.q[b] = x + half * self.l * c;
            self.q[b + 1] = y + half * self.l * s;
            self.q[b + 2] = th;
            x += self.l * c;
            y += self.l * s;
        }
        self.reset_motion();
        let lowest = self.kin.lowest_outer_y();
        for k in 0..n {
            self.q[PER * k + 1] -= lowest;
        }
        self.reset_motion();
    }

    /// Take the shape of a pin-jointed chain of the same number of links
    /// (its link angles and joint positions, bushings unstretched), at
    /// rest: to compare the two joint models at the same equilibrium.
    pub fn set_shape_from_pins<const E: usize>(&mut self, pins: &Chain<T, E>) -> Result<()> {
        if pins.links() != self.n {
            return Err(invalid(
                "pins.links",
                "the pin chain must have as many links as the bushing chain",
            ));
        }
        let hl = self.l * T::from_f64(0.5);
        for k in 0..self.n {
            let th = pins.q[TH + k];
            let (s, c) = th.sin_cos();
            let (x, y) = pins.joint_position_m(k);
            let b = PER * k;
            self.q[b] = x + hl * c;
            self.q[b + 1] = y + hl * s;
            self.q[b + 2] = th;
        }
        self.reset_motion();
        Ok(())
    }

    /// Zero velocities and accelerations and forget the integrator history.
    pub fn reset_motion(&mut self) {
        self.v = [T::ZERO; D];
        self.acc = [T::ZERO; D];
        self.history = false;
        self.h_next = self.settings.step_s;
        self.jac.invalidate();
        let (q, v) = (self.q, self.v);
        self.fill_kinematics(&q, &v);
    }

    /// Joint angle ζ at joint `j` (rad), as in [`Chain::joint_angle`](crate::Chain::joint_angle).
    pub fn joint_angle(&self, j: usize) -> T {
        let n = self.n;
        let j = j % n;
        if j == 0 {
            self.q[2] - self.q[PER * (n - 1) + 2] - self.two_pi
        } else {
            self.q[PER * j + 2] - self.q[PER * (j - 1) + 2]
        }
    }

    /// End point of link `k` (m).
    fn end_point(&self, k: usize) -> (T, T) {
        let b = PER * k;
        let hl = self.l * T::from_f64(0.5);
        (
            self.q[b] + hl * self.kin.c[k],
            self.q[b + 1] + hl * self.kin.s[k],
        )
    }

    /// Position of joint `j` (m): the midpoint of the two points the
    /// bushing joins.
    pub fn joint_position_m(&self, j: usize) -> (T, T) {
        let n = self.n;
        let j = j % n;
        let p = self.end_point((j + n - 1) % n);
        let half = T::from_f64(0.5);
        ((p.0 + self.kin.px[j]) * half, (p.1 + self.kin.py[j]) * half)
    }

    /// Stretch of the bushing at joint `j`: the distance between the two
    /// points it joins, m.
    pub fn stretch_m(&self, j: usize) -> T {
        let n = self.n;
        let j = j % n;
        let p = self.end_point((j + n - 1) % n);
        let dx = self.kin.px[j] - p.0;
        let dy = self.kin.py[j] - p.1;
        (dx * dx + dy * dy).sqrt()
    }

    /// Largest bushing stretch over all joints, m.
    pub fn max_stretch_m(&self) -> T {
        let mut best = T::ZERO;
        for j in 0..self.n {
            best = best.max(self.stretch_m(j));
        }
        best
    }

    /// Point of the outer surface at joint `j` (half the thickness off the
    /// joint, along the bisector of the two links' normals), m.
    pub fn outer_point_at_joint_m(&self, j: usize) -> (T, T) {
        let n = self.n;
        let j = j % n;
        let prev = if j == 0 {
            self.q[PER * (n - 1) + 2] + self.two_pi
        } else {
            self.q[PER * (j - 1) + 2]
        };
        let phi = (prev + self.q[PER * j + 2]) * T::from_f64(0.5);
        let (s, c) = phi.sin_cos();
        let p = self.joint_position_m(j);
        (p.0 - self.half_t * s, p.1 + self.half_t * c)
    }

    /// Height of the outer surface at A (joint 0) above the floor, m.
    pub fn a_height_m(&self) -> T {
        self.outer_point_at_joint_m(0).1
    }

    /// Overall width of the outer surface, m.
    pub fn width_m(&self) -> T {
        self.kin.outer_width()
    }

    /// Largest speed of any link's start point, m/s.
    pub fn max_joint_speed_m_s(&self) -> T {
        self.kin.max_point_speed()
    }

    /// Kinetic energy of the belt and the roller, J.
    pub fn kinetic_energy_j(&self) -> T {
        let half = T::from_f64(0.5);
        let mut e = half
            * self.roller_kg
            * (self.kin.pvx[0] * self.kin.pvx[0] + self.kin.pvy[0] * self.kin.pvy[0]);
        for k in 0..self.n {
            let b = PER * k;
            let (vx, vy, w) = (self.v[b], self.v[b + 1], self.v[b + 2]);
            e += half * self.m * (vx * vx + vy * vy) + half * self.inertia * w * w;
        }
        e
    }

    /// Potential energy, J: gravity on the links and the roller, the
    /// bushings' springs, the joints' elastic energy and the contact
    /// springs (as [`Chain::potential_energy_j`]).
    pub fn potential_energy_j(&self) -> T {
        let half = T::from_f64(0.5);
        let g = self.model.gravity_m_s2;
        let k = self.bushing.stiffness_n_per_m;
        let mut e = self.roller_kg * g * self.kin.py[0];
        for j in 0..self.n {
            e += self.m * g * self.q[PER * j + 1];
            let d = self.stretch_m(j);
            e += half * k * d * d;
            e += self.model.joint.elastic_energy_j(self.joint_angle(j));
        }
        e + self.contacts.spring_energy_j(&self.kin)
    }

    /// Kinetic plus potential energy, J.
    pub fn mechanical_energy_j(&self) -> T {
        self.kinetic_energy_j() + self.potential_energy_j()
    }

    /// How far the present state, taken at rest, is from a static
    /// equilibrium: the largest generalised force of the static equations
    /// over the weight (as [`Chain::static_imbalance`]; the bushing chain
    /// has no algebraic equations, the second figure is 0). Changes
    /// nothing in the state or the counters.
    pub fn static_imbalance(&mut self) -> (f64, f64) {
        integrator::static_imbalance(self)
    }

    fn state_is_finite(&self) -> bool {
        let ns = self.nsys();
        self.q[..ns].iter().all(|x| x.is_finite()) && self.v[..ns].iter().all(|x| x.is_finite())
    }

    /// Link start points and velocities from `(q, v)` into `self.kin`
    /// (`px[n]` is the end of the last link, for the broad phase).
    fn fill_kinematics(&mut self, q: &[T; D], v: &[T; D]) {
        let n = self.n;
        let hl = self.l * T::from_f64(0.5);
        for k in 0..n {
            let b = PER * k;
            let (s, c) = q[b + 2].sin_cos();
            let w = v[b + 2];
            self.kin.c[k] = c;
            self.kin.s[k] = s;
            self.kin.px[k] = q[b] - hl * c;
            self.kin.py[k] = q[b + 1] - hl * s;
            self.kin.pvx[k] = v[b] + hl * s * w;
            self.kin.pvy[k] = v[b + 1] - hl * c * w;
            self.kin.rate[k] = w;
        }
        let b = PER * (n - 1);
        let (c, s, w) = (self.kin.c[n - 1], self.kin.s[n - 1], v[b + 2]);
        self.kin.px[n] = q[b] + hl * c;
        self.kin.py[n] = q[b + 1] + hl * s;
        self.kin.pvx[n] = v[b] - hl * s * w;
        self.kin.pvy[n] = v[b + 1] + hl * c * w;
    }

    /// Add `sign·J_Pᵀ·f` (the generalised force of a force `f` at the point)
    /// to `out`.
    fn add_point_force(&self, out: &mut [T; D], p: Arm<T>, f: (T, T), sign: T) {
        add_point_force(&self.kin, out, p, f, sign);
    }

    /// The two points bushing `j` joins: the end of link `j−1` (P) and the
    /// start of link `j` (Q).
    fn bushing_arms(&self, j: usize) -> (Arm<T>, Arm<T>) {
        let n = self.n;
        let hl = self.l * T::from_f64(0.5);
        (
            Arm {
                link: (j + n - 1) % n,
                a: hl,
                w: T::ZERO,
            },
            Arm {
                link: j,
                a: -hl,
                w: T::ZERO,
            },
        )
    }

    /// Force of bushing `j` on P (the end of link `j−1`), N; `−F` acts on Q.
    fn bushing_force(&self, j: usize) -> (T, T) {
        let n = self.n;
        let p = (j + n - 1) % n;
        let (cp, sp) = (self.kin.c[p], self.kin.s[p]);
        let wp = self.kin.rate[p];
        // End of link p and its velocity.
        let ex = self.kin.px[p] + self.l * cp;
        let ey = self.kin.py[p] + self.l * sp;
        let evx = self.kin.pvx[p] - self.l * sp * wp;
        let evy = self.kin.pvy[p] + self.l * cp * wp;
        let k = self.bushing.stiffness_n_per_m;
        let mut fx = k * (self.kin.px[j] - ex);
        let mut fy = k * (self.kin.py[j] - ey);
        if !self.static_mode {
            let c = self.bushing.damping_n_s_per_m;
            fx += c * (self.kin.pvx[j] - evx);
            fy += c * (self.kin.pvy[j] - evy);
        }
        (fx, fy)
    }

    /// Residual of the equations of motion at positions `z`, with
    /// `v = αv·z + bv` and `a = αa·z + ba`: inertial minus applied
    /// generalised forces of every link (x, y, moment about the centre).
    fn residual(&mut self, z: &[T; D], out: &mut [T; D]) {
        self.stats.residuals += 1;
        let n = self.n;
        let ns = self.nsys();
        let g = self.model.gravity_m_s2;
        let mut vel = [T::ZERO; D];
        let mut acc = [T::ZERO; D];
        for i in 0..ns {
            vel[i] = self.alpha_v * z[i] + self.bv[i];
            acc[i] = self.alpha_a * z[i] + self.ba[i];
        }
        self.fill_kinematics(z, &vel);
        for k in 0..n {
            let b = PER * k;
            out[b] = self.m * acc[b];
            out[b + 1] = self.m * (acc[b + 1] + g);
            out[b + 2] = self.inertia * acc[b + 2];
        }
        // Roller: a point mass at the start of link 0, its inertial force
        // m_r·(a_P + g) acting there.
        if self.roller_kg > T::ZERO {
            let hl = self.l * T::from_f64(0.5);
            let (c, s) = (self.kin.c[0], self.kin.s[0]);
            let (w, wd) = (vel[2], acc[2]);
            // a_P = a_c + a·(θ̈ e' − θ̇² e), a = −l/2.
            let a = -hl;
            let apx = acc[0] + a * (-s * wd - c * w * w);
            let apy = acc[1] + a * (c * wd - s * w * w);
            let f = (self.roller_kg * apx, self.roller_kg * (apy + g));
            self.add_point_force(
                out,
                Arm {
                    link: 0,
                    a,
                    w: T::ZERO,
                },
                f,
                T::ONE,
            );
        }
        // Contacts (external forces).
        let with_velocity = !self.static_mode;
        let mut ext = [T::ZERO; D];
        self.contacts
            .for_each_contact(&self.kin, with_velocity, |kin, ct| {
                add_point_force(kin, &mut ext, arm(kin, ct.a), ct.force, T::ONE);
                if let Some(b) = ct.b {
                    add_point_force(kin, &mut ext, arm(kin, b), ct.force, -T::ONE);
                }
            });
        for i in 0..ns {
            out[i] -= ext[i];
        }
        // Bushings: F on P (end of link j−1), −F on Q (start of link j).
        for j in 0..n {
            let f = self.bushing_force(j);
            let (p, q) = self.bushing_arms(j);
            self.add_point_force(out, p, f, -T::ONE);
            self.add_point_force(out, q, f, T::ONE);
        }
        // Joint moments: +Mz on link j, −Mz on link j−1.
        let law = &self.model.joint;
        for j in 0..n {
            let p = (j + n - 1) % n;
            let (mut zeta, zr) = (
                z[PER * j + 2] - z[PER * p + 2],
                vel[PER * j + 2] - vel[PER * p + 2],
            );
            if j == 0 {
                zeta -= self.two_pi;
            }
            let jm = law.moment(zeta, if self.static_mode { T::ZERO } else { zr });
            self.kj[j] = jm.stiffness;
            self.cj[j] = jm.damping;
            out[PER * j + 2] -= jm.moment_nm;
            out[PER * p + 2] += jm.moment_nm;
        }
    }

    /// Assemble (after `residual(z)`, whose kinematics it uses) and factor
    /// the Newton matrix.
    fn assemble_jacobian(&mut self) -> Result<()> {
        self.build_jacobian();
        self.stats.factorizations += 1;
        self.scale_jacobian();
        self.band.factor(&mut self.jac)
    }

    /// Scale the θ columns by the link length and the moment rows by its
    /// inverse, so every unknown is a length (`l·θ`) and every row a force;
    /// [`Self::solve`] applies the same scaling to the right-hand side and
    /// the solution.
    fn scale_jacobian(&mut self) {
        let ns = self.nsys();
        let l = self.l;
        for row in self.jac.a.iter_mut().take(ns) {
            for k in 0..self.n {
                row[PER * k + 2] *= l;
            }
        }
        // Rows of moments: divide by l (forces, N).
        for k in 0..self.n {
            for x in self.jac.a[PER * k + 2].iter_mut().take(ns) {
                *x /= l;
            }
        }
    }

    /// Solve the scaled system in place: `r` is a residual on entry, the
    /// correction on exit.
    fn solve(&self, r: &mut [T; D]) {
        for k in 0..self.n {
            r[PER * k + 2] /= self.l;
        }
        self.band.solve(&self.jac, r);
        for k in 0..self.n {
            r[PER * k + 2] *= self.l;
        }
    }

    /// The Newton matrix `∂R/∂z` at the state of the last residual.
    fn build_jacobian(&mut self) {
        let n = self.n;
        let ns = self.nsys();
        let aa = self.alpha_a;
        let av = if self.static_mode {
            T::ZERO
        } else {
            self.alpha_v
        };
        self.jac.reset(ns);
        for k in 0..n {
            let b = PER * k;
            self.jac.a[b][b] += aa * self.m;
            self.jac.a[b + 1][b + 1] += aa * self.m;
            self.jac.a[b + 2][b + 2] += aa * self.inertia;
        }
        if self.roller_kg > T::ZERO {
            let hl = self.l * T::from_f64(0.5);
            let arm = Arm {
                link: 0,
                a: -hl,
                w: T::ZERO,
            };
            for d in [(T::ONE, T::ZERO), (T::ZERO, T::ONE)] {
                let mut gr = Grad::new();
                push_grad(&self.kin, &mut gr, arm, d, T::ONE);
                rank_one(&mut self.jac, &gr, aa * self.roller_kg);
            }
        }
        // Joint moments: tridiagonal in θ with the closing corner.
        for j in 0..n {
            let d = self.kj[j] + av * self.cj[j];
            let (i, p) = (PER * j + 2, PER * ((j + n - 1) % n) + 2);
            self.jac.a[i][i] += d;
            self.jac.a[p][p] += d;
            self.jac.a[i][p] -= d;
            self.jac.a[p][i] -= d;
        }
        // Bushings: (k + αv·c)·Gᵀ G per axis, G = ∂(Q − P)/∂z, plus the
        // geometric terms of the forces at the turning lever arms.
        let kb = self.bushing.stiffness_n_per_m + av * self.bushing.damping_n_s_per_m;
        for j in 0..n {
            let (p, q) = self.bushing_arms(j);
            for d in [(T::ONE, T::ZERO), (T::ZERO, T::ONE)] {
                let mut gr = Grad::new();
                push_grad(&self.kin, &mut gr, q, d, T::ONE);
                push_grad(&self.kin, &mut gr, p, d, -T::ONE);
                rank_one(&mut self.jac, &gr, kb);
            }
            let f = self.bushing_force(j);
            geometric(&self.kin, &mut self.jac, p, f, -T::ONE);
            geometric(&self.kin, &mut self.jac, q, f, T::ONE);
        }
        // Contacts: normal (and friction) rank-one terms, geometric terms.
        let with_velocity = !self.static_mode;
        let jac = &mut self.jac;
        self.contacts
            .for_each_contact(&self.kin, with_velocity, |kin, ct| {
                let a = arm(kin, ct.a);
                let b = ct.b.map(|b| arm(kin, b));
                let mut gn = Grad::new();
                push_grad(kin, &mut gn, a, ct.normal, T::ONE);
                let mut gt = Grad::new();
                push_grad(kin, &mut gt, a, ct.tangent, T::ONE);
                if let Some(b) = b {
                    push_grad(kin, &mut gn, b, ct.normal, -T::ONE);
                    push_grad(kin, &mut gt, b, ct.tangent, -T::ONE);
                }
                rank_one(jac, &gn, ct.kn + av * ct.cn);
                rank_one(jac, &gt, av * ct.ct);
                // The residual holds −J_aᵀ f (and +J_bᵀ f).
                geometric(kin, jac, a, ct.force, -T::ONE);
                if let Some(b) = b {
                    geometric(kin, jac, b, ct.force, T::ONE);
                }
            });
        self.jac_alpha = (self.alpha_a, av);
    }

    /// Advance by one nominal step (see [`Chain::step`](crate::Chain::step)).
    pub fn step(&mut self) -> Result<()> {
        self.step_max(self.settings.step_s)
    }

    /// Advance by one BDF2 step of at most `h_max` seconds (the integrator
    /// of [`Chain::step_max`](crate::Chain::step_max), see
    /// [`crate::integrator`]).
    pub fn step_max(&mut self, h_max: T) -> Result<()> {
        integrator::step_max(self, h_max)
    }

    /// Find the static equilibrium nearest the current shape and leave the
    /// chain there at rest (dynamic relaxation, then the Newton polish of
    /// [`Chain::solve_static`](crate::Chain::solve_static)).
    /// Returns the number of proximal iterations.
    pub fn solve_static(&mut self) -> Result<usize> {
        integrator::solve_static(self)
    }
}

impl<T: Real, const D: usize> Implicit<T, D> for BushingChain<T, D> {
    const STATIC_WHAT: &'static str = "static equilibrium (bushing chain)";

    /// Every unknown is a coordinate (no constraints).
    fn ndof(&self) -> usize {
        self.nsys()
    }
    fn nsys(&self) -> usize {
        BushingChain::nsys(self)
    }
    /// Everything but the link angles.
    fn is_length_coord(&self, i: usize) -> bool {
        i % PER != 2
    }
    integrator::implicit_fields!();
    /// The bushings are the stiffest springs.
    fn stiffest_spring_n_per_m(&self) -> f64 {
        let m = &self.model;
        m.floor
            .stiffness_n_per_m
            .to_f64()
            .max(m.self_contact.stiffness_n_per_m.to_f64())
            .max(self.bushing.stiffness_n_per_m.to_f64())
    }
    fn residual(&mut self, z: &[T; D], out: &mut [T; D]) {
        BushingChain::residual(self, z, out)
    }
    /// The kinematics of the last residual are those of `z`.
    fn assemble_jacobian(&mut self, _z: &[T; D]) -> Result<()> {
        BushingChain::assemble_jacobian(self)
    }
    fn solve(&self, r: &mut [T; D]) {
        BushingChain::solve(self, r)
    }
    fn update_kinematics(&mut self) {
        let (q, v) = (self.q, self.v);
        self.fill_kinematics(&q, &v);
    }
    fn reset_motion(&mut self) {
        BushingChain::reset_motion(self)
    }
    fn kinetic_energy_j(&self) -> T {
        BushingChain::kinetic_energy_j(self)
    }
    fn max_joint_speed_m_s(&self) -> T {
        BushingChain::max_joint_speed_m_s(self)
    }
    fn state_is_finite(&self) -> bool {
        BushingChain::state_is_finite(self)
    }
}

/// Position in the Newton matrix of every unknown of an `n`-link chain:
/// links in folded order 0, N−1, 1, N−2, … Neighbours in the loop are at
/// most two blocks apart, so the matrix is banded (apart from
/// self-contacts) and the LU, which skips zero multipliers, costs about N²
/// instead of N³.
fn folded_order<const D: usize>(n: usize) -> [usize; D] {
    let mut perm = [0; D];
    for i in 0..n {
        let link = if i % 2 == 0 { i / 2 } else { n - 1 - i / 2 };
        for c in 0..PER {
            perm[PER * link + c] = PER * i + c;
        }
    }
    perm
}

/// Arm of a link point (`u` from the link's start) from the link's centre.
fn arm<T: Real, const D: usize>(kin: &Kinematics<T, D>, p: LinkPoint<T>) -> Arm<T> {
    Arm {
        link: p.link,
        a: p.u - kin.l * T::from_f64(0.5),
        w: p.w,
    }
}

/// `sign·J_Pᵀ·d` of a link point: the generalised force of a force `d`
/// there on its link's `(x, y, θ)`, and the index of that link's `x`.
fn point_jt<T: Real, const D: usize>(
    kin: &Kinematics<T, D>,
    p: Arm<T>,
    d: (T, T),
    sign: T,
) -> (usize, [T; PER]) {
    let k = p.link;
    let (c, s) = (kin.c[k], kin.s[k]);
    // r = a e + w e', dr/dθ = a e' − w e; e = (c, s), e' = (−s, c).
    (
        PER * k,
        [
            sign * d.0,
            sign * d.1,
            sign * (p.a * (-s * d.0 + c * d.1) - p.w * (c * d.0 + s * d.1)),
        ],
    )
}

/// Add `sign·J_Pᵀ·f` (the generalised force of a force `f` at the point) to
/// `out`.
fn add_point_force<T: Real, const D: usize>(
    kin: &Kinematics<T, D>,
    out: &mut [T; D],
    p: Arm<T>,
    f: (T, T),
    sign: T,
) {
    let (b, g) = point_jt(kin, p, f, sign);
    for (o, x) in out[b..b + PER].iter_mut().zip(g) {
        *o += x;
    }
}

/// `sign·∂(J_Pᵀ f)/∂θ` with `f` held fixed (geometric stiffness), on the
/// link's θθ entry.
fn geometric<T: Real, const D: usize>(
    kin: &Kinematics<T, D>,
    jac: &mut Dense<T, D>,
    p: Arm<T>,
    f: (T, T),
    sign: T,
) {
    let k = p.link;
    let (c, s) = (kin.c[k], kin.s[k]);
    let i = PER * k + 2;
    jac.a[i][i] += sign * (-p.a * (c * f.0 + s * f.1) - p.w * (-s * f.0 + c * f.1));
}

/// Gradient of `d·P` (a point's position along direction `d`).
fn push_grad<T: Real, const D: usize>(
    kin: &Kinematics<T, D>,
    g: &mut Grad<T>,
    p: Arm<T>,
    d: (T, T),
    sign: T,
) {
    let (b, v) = point_jt(kin, p, d, sign);
    for (c, x) in v.into_iter().enumerate() {
        g.push(b + c, x);
    }
}

/// `coef·g·gᵀ` into the Newton matrix.
fn rank_one<T: Real, const D: usize>(jac: &mut Dense<T, D>, g: &Grad<T>, coef: T) {
    if coef == T::ZERO {
        return;
    }
    for r in 0..g.len {
        let gi = coef * g.val[r];
        let row = &mut jac.a[g.idx[r]];
        for cc in 0..g.len {
            row[g.idx[cc]] += gi * g.val[cc];
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::params::{Method, Variant};

    type Small = BushingChain<f64, 114>;

    fn chain() -> std::boxed::Box<Small> {
        let model = Model::paper(Variant::E38, Method::I).unwrap();
        std::boxed::Box::new(Small::new(model, Bushing::paper(), Settings::default()).unwrap())
    }

    /// Largest deviation of the analytic Newton matrix from central
    /// differences of the residual, relative to the column's largest entry.
    fn fd_error(c: &mut Small, z: [f64; 114]) -> f64 {
        let ns = c.nsys();
        let mut r0 = [0.0; 114];
        c.residual(&z, &mut r0);
        c.build_jacobian();
        let mut worst = 0.0f64;
        for j in 0..ns {
            let h = 1e-8;
            let (mut zp, mut zm) = (z, z);
            zp[j] += h;
            zm[j] -= h;
            let (mut r1, mut r2) = ([0.0; 114], [0.0; 114]);
            c.residual(&zp, &mut r1);
            c.residual(&zm, &mut r2);
            c.residual(&z, &mut r0);
            c.build_jacobian();
            let colmax = (0..ns).map(|i| c.jac.a[i][j].abs()).fold(0.0, f64::max);
            for i in 0..ns {
                let fd = (r1[i] - r2[i]) / (2.0 * h);
                worst = worst.max((fd - c.jac.a[i][j]).abs() / (colmax + 1e-12));
            }
        }
        worst
    }

    #[test]
    fn newton_matrix_matches_finite_differences() {
        let mut c = chain();
        let ns = c.nsys();
        let mut z = c.q;
        for i in 0..ns {
            z[i] += 1e-6 * ((i * 7) as f64).sin();
        }
        c.static_mode = true;
        c.alpha_v = 0.0;
        c.alpha_a = 400.0;
        for i in 0..ns {
            c.bv[i] = 0.0;
            c.ba[i] = -400.0 * c.q[i];
        }
        let e = fd_error(&mut c, z);
        assert!(e < 1e-5, "static: {e:e}");
        c.static_mode = false;
        c.alpha_v = 750.0;
        c.alpha_a = 750.0 * 750.0;
        for i in 0..ns {
            c.bv[i] = -750.0 * z[i] + 0.01 * ((i * 3) as f64).cos();
            c.ba[i] = -c.alpha_a * z[i] + 0.1 * ((i * 5) as f64).cos();
        }
        let e = fd_error(&mut c, z);
        // Small terms are left out on purpose (the turning of the damper's
        // lever arms, the roller's centripetal term): about 1e-5 here.
        assert!(e < 1e-4, "dynamic: {e:e}");
    }

    #[test]
    fn circle_starts_unstretched_and_capacity_is_checked() {
        let c = chain();
        assert!(c.max_stretch_m() < 1e-12, "{}", c.max_stretch_m());
        assert!((c.joint_angle(0) + c.joint_angle(1) * 37.0 + core::f64::consts::TAU).abs() < 1e-9);
        let model = Model::paper(Variant::E56, Method::I).unwrap();
        assert!(matches!(
            Small::new(model, Bushing::paper(), Settings::default()),
            Err(Error::Capacity { .. })
        ));
        let model = Model::paper(Variant::E38, Method::I).unwrap();
        let bad = Bushing {
            stiffness_n_per_m: f64::NAN,
            damping_n_s_per_m: 1.0,
        };
        assert!(Small::new(model, bad, Settings::default()).is_err());
    }
}

//! The bending-resistance rig (paper section 6.2): the belt wrapped round a
//! drive wheel and an idler, no ground; the drive is brought to a speed and
//! held, and the torque it needs is the belt's bending resistance.
//!
//! # Geometry and choices (the paper gives neither axle distance nor tension)
//!
//! * The drive wheel is centred at the origin and turns clockwise (positive
//!   speed), so the top run moves from the drive towards the idler.
//! * The idler sits on a **tensioner**: its axle slides along x and a
//!   constant force ([`RigConfig::idler_force_n`], 500 N by default) pulls it
//!   away from the drive. Each run then carries about half of it. The axle
//!   distance follows from the belt length (≈ 0.74 m for the shredder belt on
//!   two 300 mm wheels).
//! * The belt's inner surface touches the wheels through a stiff penalty
//!   contact at the point of each link's inner edge closest to the wheel's
//!   centre. The drive wheel drives the belt by regularised Coulomb friction;
//!   the idler is frictionless (a free-running idler with negligible inertia
//!   and bearing friction).
//! * Gravity acts in the plane of the rig (the wheels side by side).
//! * The drive torque is the moment of the contact forces about the drive
//!   axle, plus an optional constant bearing friction.
//!
//! # Example
//!
//! ```
//! use trackbelt::params::{Method, Model, Variant};
//! use trackbelt::rig::{rig_test, Rig, RigConfig, RigTest};
//! use trackbelt::{Chain, Settings};
//!
//! let model = Model::<f64>::paper(Variant::E38, Method::I)?;
//! let mut rig: Rig<f64, 48> = Rig::new(model, RigConfig::default(), Settings::default())?;
//! let test = RigTest { speed_rad_s: 2.0, ramp_s: 0.5, hold_s: 0.5, settle_s: 0.2 };
//! let figures = rig_test(&mut rig, &test, |_| {})?;
//! assert!(figures.torque_nm_mean > 0.0);
//! # Ok::<(), trackbelt::Error>(())
//! ```

use crate::chain::{CentreHold, Chain, GroundAxle, IdlerAxle};
use crate::contact::{ContactKind, FixedWheel, GroundContact, Wheels, MAX_FIXED_WHEELS};
use crate::error::{invalid, Error, Result};
use crate::gear::{RunningGear, Tensioner, WheelRole, MAX_WHEELS};
use crate::integrator::{step_until, Settings};
use crate::kinematics::{TH, X, Y};
use crate::params::Model;
use crate::real::Real;

/// The rig's parameters (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RigConfig<T> {
    /// Drive wheel diameter, m (the paper: 0.3).
    pub drive_diameter_m: T,
    /// Idler diameter, m (the paper: 0.3).
    pub idler_diameter_m: T,
    /// Tensioner force pulling the idler axle away from the drive, N.
    pub idler_force_n: T,
    /// Mass moving with the idler axle, kg.
    pub idler_mass_kg: T,
    /// Viscous damping of the idler's slider, N·s/m.
    pub idler_damping_n_s_per_m: T,
    /// Normal stiffness of the belt–wheel contact, N/m.
    pub wheel_stiffness_n_per_m: T,
    /// Normal damping of the belt–wheel contact, N·s/m.
    pub wheel_damping_n_s_per_m: T,
    /// Friction coefficient between belt and drive wheel.
    pub drive_friction: T,
    /// Slip speed below which the drive friction is regularised, m/s.
    pub slip_speed_m_s: T,
    /// Constant resisting torque of the wheel bearings, referred to the
    /// drive axle, N·m (0: none; the baseline model has none).
    pub bearing_friction_nm: T,
}

impl<T: Real> Default for RigConfig<T> {
    fn default() -> Self {
        RigConfig {
            drive_diameter_m: T::from_f64(0.3),
            idler_diameter_m: T::from_f64(0.3),
            idler_force_n: T::from_f64(500.0),
            idler_mass_kg: T::from_f64(2.0),
            idler_damping_n_s_per_m: T::from_f64(2000.0),
            wheel_stiffness_n_per_m: T::from_f64(1.0e6),
            wheel_damping_n_s_per_m: T::from_f64(200.0),
            drive_friction: T::from_f64(1.0),
            slip_speed_m_s: T::from_f64(0.005),
            bearing_friction_nm: T::ZERO,
        }
    }
}

impl<T: Real> RigConfig<T> {
    /// Check every field (positive and finite where it must be).
    ///
    /// ```
    /// use trackbelt::rig::RigConfig;
    /// let mut c = RigConfig::<f64>::default();
    /// c.idler_force_n = f64::NAN;
    /// assert!(c.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<()> {
        let pos = |x: T| x.is_finite() && x > T::ZERO;
        let nonneg = |x: T| x.is_finite() && x >= T::ZERO;
        let checks: [(&'static str, bool); 10] = [
            ("rig.drive_diameter_m", pos(self.drive_diameter_m)),
            ("rig.idler_diameter_m", pos(self.idler_diameter_m)),
            ("rig.idler_force_n", pos(self.idler_force_n)),
            ("rig.idler_mass_kg", pos(self.idler_mass_kg)),
            (
                "rig.idler_damping_n_s_per_m",
                nonneg(self.idler_damping_n_s_per_m),
            ),
            (
                "rig.wheel_stiffness_n_per_m",
                pos(self.wheel_stiffness_n_per_m),
            ),
            (
                "rig.wheel_damping_n_s_per_m",
                nonneg(self.wheel_damping_n_s_per_m),
            ),
            ("rig.drive_friction", pos(self.drive_friction)),
            ("rig.slip_speed_m_s", pos(self.slip_speed_m_s)),
            ("rig.bearing_friction_nm", nonneg(self.bearing_friction_nm)),
        ];
        for (field, ok) in checks {
            if !ok {
                return Err(invalid(
                    field,
                    "must be finite and positive (damping, bearing friction: not negative)",
                ));
            }
        }
        Ok(())
    }

    /// The same configuration in another number type.
    pub fn cast<U: Real>(&self) -> RigConfig<U> {
        let c = |x: T| U::from_f64(x.to_f64());
        RigConfig {
            drive_diameter_m: c(self.drive_diameter_m),
            idler_diameter_m: c(self.idler_diameter_m),
            idler_force_n: c(self.idler_force_n),
            idler_mass_kg: c(self.idler_mass_kg),
            idler_damping_n_s_per_m: c(self.idler_damping_n_s_per_m),
            wheel_stiffness_n_per_m: c(self.wheel_stiffness_n_per_m),
            wheel_damping_n_s_per_m: c(self.wheel_damping_n_s_per_m),
            drive_friction: c(self.drive_friction),
            slip_speed_m_s: c(self.slip_speed_m_s),
            bearing_friction_nm: c(self.bearing_friction_nm),
        }
    }
}

/// The belt on the rig: a [`Chain`] with the two wheels and the idler's
/// axle as an extra coordinate. Needs `D ≥ N + 5`.
pub struct Rig<T: Real, const D: usize> {
    chain: Chain<T, D>,
    config: RigConfig<T>,
    /// How far the idler moved from the laid-out axle distance while the
    /// belt settled (contact compression), m: later lay-outs start there.
    idler_offset_m: f64,
    /// The wheels' lay-out: the paper's two wheels, or a running gear's.
    layout: Layout,
    /// How far the ground rose above the belt's lowest outer point while
    /// the belt settled, m (a running gear with ground).
    ground_offset_m: f64,
    /// A fixed-centre tensioner: the idler's given centre distance, m.
    fixed_centre_m: Option<f64>,
}

/// A fixed idler centre is held by a spring this many times stiffer than
/// the belt–wheel contact (1e9 N/m for the default 1e6 N/m), critically
/// damped for the idler's mass: the belt's pull moves the idler by well
/// under a micrometre (0.4 µm at 400 N), and the tension follows from the
/// belt's length against the path (the links are inextensible; the
/// contacts' compliance takes up the difference).
pub const FIXED_CENTRE_STIFFNESS_FACTOR: f64 = 1.0e3;

/// A fixed-centre belt whose pretension at rest is below this many times
/// its weight hangs slack: an error (too long for the centre).
pub const FIXED_CENTRE_MIN_PRETENSION_PER_WEIGHT: f64 = 1.0;

/// A belt this much shorter than the path round the wheels at a fixed
/// idler centre (mm of path length) is an error: the contacts would have to
/// compress beyond the penalty law's range to take it up.
pub const FIXED_CENTRE_SHORT_TOL_MM: f64 = 2.0;

/// Where the wheels are (f64; set-up only).
// No heap in the core: the gear's 248 bytes sit beside a Jacobian of
// 8·D² bytes.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy)]
enum Layout {
    /// The paper's rig: drive at the origin, idler on +x (the closed-form
    /// [`Path`]).
    TwoWheel,
    /// A running gear: drive at the origin, the idler sliding along
    /// `(ux, uy)`, the other wheels fixed (the convex [`Hull`]).
    Gear(GearLayout),
}

/// A running gear's wheels relative to the drive's centre, m.
#[derive(Debug, Clone, Copy)]
struct GearLayout {
    /// Centres (the idler's at distance 1 along `u`: it is scaled by the
    /// axle distance) and diameters, in the gear's order.
    x: [f64; MAX_WHEELS],
    y: [f64; MAX_WHEELS],
    diameter: [f64; MAX_WHEELS],
    count: usize,
    drive: usize,
    idler: usize,
    /// The idler's sliding direction (unit).
    ux: f64,
    uy: f64,
    /// The ground's upward force (the weight carried), N, when there is
    /// ground.
    ground_n: Option<f64>,
}

/// The closed path of the link joints round the two wheels (f64; set-up only).
#[derive(Debug, Clone, Copy)]
struct Path {
    /// Joint radius on the drive and on the idler, m.
    r1: f64,
    r2: f64,
    /// Axle distance, m.
    d: f64,
    /// Unit normal of the top run (pointing up/outwards).
    nx: f64,
    ny: f64,
    /// Angle of the top-run normal, rad.
    a: f64,
}

impl Path {
    fn new(r1: f64, r2: f64, d: f64) -> Option<Path> {
        let nx = (r1 - r2) / d;
        if nx.is_nan() || nx.abs() >= 0.99 {
            return None;
        }
        let ny = libm::sqrt(1.0 - nx * nx);
        Some(Path {
            r1,
            r2,
            d,
            nx,
            ny,
            a: libm::atan2(ny, nx),
        })
    }

    fn run_len(&self) -> f64 {
        // Length of each straight run between the tangent points.
        let dx = self.d + (self.r2 - self.r1) * self.nx;
        let dy = (self.r2 - self.r1) * self.ny;
        libm::sqrt(dx * dx + dy * dy)
    }

    fn len(&self) -> f64 {
        2.0 * self.run_len()
            + self.r2 * 2.0 * self.a
            + self.r1 * (2.0 * core::f64::consts::PI - 2.0 * self.a)
    }

    /// Arc length from the middle of the top run to where the path meets
    /// the drive wheel (the bottom run's end).
    fn drive_start_s(&self) -> f64 {
        1.5 * self.run_len() + self.r2 * 2.0 * self.a
    }

    /// Point at arc length `s` from the middle of the top run, clockwise.
    fn point(&self, s: f64) -> (f64, f64) {
        let total = self.len();
        let mut s = s % total;
        if s < 0.0 {
            s += total;
        }
        let run = self.run_len();
        let (t1x, t1y) = (self.r1 * self.nx, self.r1 * self.ny);
        let (t2x, t2y) = (self.d + self.r2 * self.nx, self.r2 * self.ny);
        let (ux, uy) = ((t2x - t1x) / run, (t2y - t1y) / run);
        // Top run, second half.
        if s < run / 2.0 {
            let u = run / 2.0 + s;
            return (t1x + ux * u, t1y + uy * u);
        }
        s -= run / 2.0;
        // Round the idler, clockwise from angle a to −a.
        let arc2 = self.r2 * 2.0 * self.a;
        if s < arc2 {
            let phi = self.a - s / self.r2;
            let (sn, cs) = libm::sincos(phi);
            return (self.d + self.r2 * cs, self.r2 * sn);
        }
        s -= arc2;
        // Bottom run, idler to drive.
        if s < run {
            let (bx, by) = (self.d + self.r2 * self.nx, -self.r2 * self.ny);
            let (ex, ey) = (self.r1 * self.nx, -self.r1 * self.ny);
            let f = s / run;
            return (bx + (ex - bx) * f, by + (ey - by) * f);
        }
        s -= run;
        // Round the drive, clockwise from −a to a − 2π.
        let arc1 = self.r1 * (2.0 * core::f64::consts::PI - 2.0 * self.a);
        if s < arc1 {
            let phi = -self.a - s / self.r1;
            let (sn, cs) = libm::sincos(phi);
            return (self.r1 * cs, self.r1 * sn);
        }
        s -= arc1;
        (t1x + ux * s, t1y + uy * s)
    }

    /// Walk `n` chords of length `l` from `s0`; returns the arc length
    /// reached, and fills the joints' arc positions.
    fn walk(&self, n: usize, l: f64, s0: f64, out: &mut [f64]) -> f64 {
        let mut s = s0;
        for slot in out.iter_mut().take(n + 1) {
            *slot = s;
            let p = self.point(s);
            let (mut lo, mut hi) = (s, s + 1.6 * l);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                let q = self.point(mid);
                let dist = libm::hypot(q.0 - p.0, q.1 - p.1);
                if dist < l {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            s = 0.5 * (lo + hi);
        }
        out[n]
    }
}

/// A closed path round the wheels: the arcs and tangent segments of the
/// convex hull of circles (each wheel's joint-polygon radius), traversed
/// clockwise from the start of the drive's arc.
#[derive(Debug, Clone, Copy)]
struct Hull {
    /// Wheels on the hull, in path order (node 0: the drive).
    m: usize,
    cx: [f64; MAX_WHEELS],
    cy: [f64; MAX_WHEELS],
    rho: [f64; MAX_WHEELS],
    /// Polar angle where the path arrives on each wheel, rad, and the
    /// angle it wraps clockwise, rad.
    a_in: [f64; MAX_WHEELS],
    sweep: [f64; MAX_WHEELS],
    /// Outward normal of the tangent leaving each wheel.
    nx: [f64; MAX_WHEELS],
    ny: [f64; MAX_WHEELS],
    /// Length of the tangent leaving each wheel, m.
    seg: [f64; MAX_WHEELS],
    total: f64,
}

impl Hull {
    /// The hull of circles `(x, y, rho)`, starting at circle `first`.
    /// `None` when the circles give no closed convex path.
    fn new(c: &[(f64, f64, f64)], first: usize) -> Option<Hull> {
        let k = c.len();
        if !(2..=MAX_WHEELS).contains(&k) || first >= k {
            return None;
        }
        // The outward normal of the tangent from circle i to circle j with
        // the hull on the right (clockwise travel).
        let tangent = |i: usize, j: usize| -> Option<(f64, f64, f64)> {
            let (dx, dy) = (c[j].0 - c[i].0, c[j].1 - c[i].1);
            let len = libm::hypot(dx, dy);
            let a = (c[i].2 - c[j].2) / len;
            if !(len > 0.0 && a.abs() < 0.99) {
                return None;
            }
            let b = libm::sqrt(1.0 - a * a);
            let (ex, ey) = (dx / len, dy / len);
            let (nx, ny) = (a * ex - b * ey, a * ey + b * ex);
            // Every other circle inside.
            for (o, co) in c.iter().enumerate() {
                if o != i
                    && o != j
                    && (co.0 - c[i].0) * nx + (co.1 - c[i].1) * ny + co.2 > c[i].2 + 1e-9
                {
                    return None;
                }
            }
            // Length of the tangent segment.
            let (tx, ty) = (dx + (c[j].2 - c[i].2) * nx, dy + (c[j].2 - c[i].2) * ny);
            Some((nx, ny, libm::hypot(tx, ty)))
        };
        let mut order = [0usize; MAX_WHEELS];
        let mut nrm = [(0.0f64, 0.0f64, 0.0f64); MAX_WHEELS];
        let mut m = 0;
        let mut at = first;
        loop {
            // The successor: a hull tangent, the nearest when several lie
            // on one line.
            let mut best: Option<(usize, (f64, f64, f64))> = None;
            for j in 0..k {
                if j == at {
                    continue;
                }
                if let Some(t) = tangent(at, j) {
                    if best.is_none_or(|(_, b)| t.2 < b.2) {
                        best = Some((j, t));
                    }
                }
            }
            let (next, t) = best?;
            if m >= MAX_WHEELS || order[..m].contains(&at) {
                return None;
            }
            order[m] = at;
            nrm[m] = t;
            m += 1;
            at = next;
            if at == first {
                break;
            }
        }
        let mut h = Hull {
            m,
            cx: [0.0; MAX_WHEELS],
            cy: [0.0; MAX_WHEELS],
            rho: [0.0; MAX_WHEELS],
            a_in: [0.0; MAX_WHEELS],
            sweep: [0.0; MAX_WHEELS],
            nx: [0.0; MAX_WHEELS],
            ny: [0.0; MAX_WHEELS],
            seg: [0.0; MAX_WHEELS],
            total: 0.0,
        };
        for p in 0..m {
            let w = c[order[p]];
            h.cx[p] = w.0;
            h.cy[p] = w.1;
            h.rho[p] = w.2;
            h.nx[p] = nrm[p].0;
            h.ny[p] = nrm[p].1;
            h.seg[p] = nrm[p].2;
        }
        for p in 0..m {
            let prev = if p == 0 { m - 1 } else { p - 1 };
            let a_in = libm::atan2(h.ny[prev], h.nx[prev]);
            let a_out = libm::atan2(h.ny[p], h.nx[p]);
            let mut sweep = a_in - a_out;
            while sweep < 0.0 {
                sweep += core::f64::consts::TAU;
            }
            while sweep >= core::f64::consts::TAU {
                sweep -= core::f64::consts::TAU;
            }
            h.a_in[p] = a_in;
            h.sweep[p] = sweep;
            h.total += h.rho[p] * sweep + h.seg[p];
        }
        Some(h)
    }
}

/// A closed path the belt's joints are laid along.
trait Loop {
    /// Its length, m.
    fn len(&self) -> f64;
    /// The point at arc length `s` (any real; wraps round), m.
    fn point(&self, s: f64) -> (f64, f64);

    /// Walk `n` chords of length `l` from `s0`; returns the arc length
    /// reached, and fills the joints' arc positions.
    fn walk(&self, n: usize, l: f64, s0: f64, out: &mut [f64]) -> f64 {
        let mut s = s0;
        for slot in out.iter_mut().take(n + 1) {
            *slot = s;
            let p = self.point(s);
            let (mut lo, mut hi) = (s, s + 1.6 * l);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                let q = self.point(mid);
                let dist = libm::hypot(q.0 - p.0, q.1 - p.1);
                if dist < l {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            s = 0.5 * (lo + hi);
        }
        out[n]
    }
}

impl Loop for Path {
    fn len(&self) -> f64 {
        Path::len(self)
    }
    fn point(&self, s: f64) -> (f64, f64) {
        Path::point(self, s)
    }
    fn walk(&self, n: usize, l: f64, s0: f64, out: &mut [f64]) -> f64 {
        Path::walk(self, n, l, s0, out)
    }
}

impl Loop for Hull {
    fn len(&self) -> f64 {
        self.total
    }
    fn point(&self, s: f64) -> (f64, f64) {
        let mut s = s % self.total;
        if s < 0.0 {
            s += self.total;
        }
        for p in 0..self.m {
            let arc = self.rho[p] * self.sweep[p];
            if s < arc {
                let phi = self.a_in[p] - s / self.rho[p];
                let (sn, cs) = libm::sincos(phi);
                return (self.cx[p] + self.rho[p] * cs, self.cy[p] + self.rho[p] * sn);
            }
            s -= arc;
            let next = if p + 1 == self.m { 0 } else { p + 1 };
            if s < self.seg[p] || next == 0 {
                let (ax, ay) = (
                    self.cx[p] + self.rho[p] * self.nx[p],
                    self.cy[p] + self.rho[p] * self.ny[p],
                );
                let (bx, by) = (
                    self.cx[next] + self.rho[next] * self.nx[p],
                    self.cy[next] + self.rho[next] * self.ny[p],
                );
                let f = if self.seg[p] > 0.0 {
                    s / self.seg[p]
                } else {
                    0.0
                };
                return (ax + (bx - ax) * f, ay + (by - ay) * f);
            }
            s -= self.seg[p];
        }
        (self.cx[0], self.cy[0])
    }
}

/// Outer iterations a rig's static solve may spend ([`rig_settings`]; the
/// integrator's default, for a free belt, is 400). A belt on a strong
/// tensioner settles slowly: the proximal polish creeps along the belt's
/// circulation round the wheels, and truth seed 9009's rig (a 1764 mm,
/// 2.64 kg belt on 246/220 mm wheels, E38 table) needed 536 iterations at
/// 759 N and 919 at 1000 N; truth seed 79011's (a 2172 mm, 5.25 kg belt
/// on 248/348 mm wheels) did not settle in 2000 at 369–375 N, though it did
/// at 365 and 380 N, and settles within this limit. Runs that settle
/// earlier are unchanged (the solve stops where it converges); one that
/// does not settle still ends in a typed error, after at most this many.
pub const RIG_STATIC_ITERATIONS: usize = 4000;

/// The integrator settings for a rig or running gear: the defaults with
/// [`RIG_STATIC_ITERATIONS`]. The estimator's table builders use them; pass
/// them to [`Rig::new`] and [`Rig::from_gear`] unless you have your own.
///
/// ```
/// use trackbelt::rig::{rig_settings, RIG_STATIC_ITERATIONS};
/// let s = rig_settings::<f64>();
/// assert_eq!(s.static_iterations, RIG_STATIC_ITERATIONS);
/// assert_eq!(s.step_s, trackbelt::Settings::<f64>::default().step_s);
/// ```
pub fn rig_settings<T: Real>() -> Settings<T> {
    Settings {
        static_iterations: RIG_STATIC_ITERATIONS,
        ..Settings::default()
    }
}

impl<T: Real, const D: usize> Rig<T, D> {
    /// The belt of `model` on the rig, settled at rest (static equilibrium
    /// with the tensioner pulling).
    pub fn new(model: Model<T>, config: RigConfig<T>, settings: Settings<T>) -> Result<Self> {
        config.validate()?;
        let n = model.belt.links;
        if n + 5 > D {
            return Err(Error::Capacity {
                what: "rig unknowns (links + 5)",
                requested: n + 5,
                capacity: D,
            });
        }
        let mut chain = Chain::new(model, settings)?;
        chain.contacts.floor_enabled = false;
        chain.contacts.self_contact.enabled = false;
        chain.idler = Some(IdlerAxle {
            mass_kg: config.idler_mass_kg,
            damping_n_s_per_m: config.idler_damping_n_s_per_m,
            force_n: config.idler_force_n,
            hold: None,
        });
        let half = T::from_f64(0.5);
        chain.contacts.wheels = Some(Wheels {
            drive_r: config.drive_diameter_m * half,
            idler_r: config.idler_diameter_m * half,
            idler_x: T::ZERO,
            idler_vx: T::ZERO,
            drive_omega: T::ZERO,
            stiffness: config.wheel_stiffness_n_per_m,
            damping: config.wheel_damping_n_s_per_m,
            friction: config.drive_friction,
            slip_speed: config.slip_speed_m_s,
            idler_ux: T::ONE,
            idler_uy: T::ZERO,
            fixed: [FixedWheel {
                x: T::ZERO,
                y: T::ZERO,
                r: T::ZERO,
            }; MAX_FIXED_WHEELS],
            fixed_count: 0,
        });
        let mut rig = Rig {
            chain,
            config,
            idler_offset_m: 0.0,
            layout: Layout::TwoWheel,
            ground_offset_m: 0.0,
            fixed_centre_m: None,
        };
        let d = rig.lay_out(0.0)?;
        rig.chain.solve_static()?;
        rig.idler_offset_m = rig.idler_position_m().to_f64() - d;
        Ok(rig)
    }

    /// The belt of `model` on a running gear, settled at rest (static
    /// equilibrium with the tensioner pushing the idler out and, with
    /// ground, the robot's weight pressing the road wheels onto it). Needs
    /// `D ≥ N + 5`, one more with ground.
    ///
    /// The paper's two-wheel rig (see
    /// [`RunningGear::two_wheel_rig_config`]) is exactly [`Rig::new`]; any
    /// other gear is laid out on the convex hull of its wheels. The drive
    /// wheel's centre is the origin of the rig's frame (the gear is
    /// shifted; y stays up, gravity −y).
    ///
    /// A [`Tensioner::FixedCentre`] idler is held at its given centre by a
    /// stiff, critically damped spring (see
    /// [`FIXED_CENTRE_STIFFNESS_FACTOR`]) instead of the constant force:
    /// the belt's tension follows from its length against the path round
    /// the wheels (the pretension when the path is longer than the belt
    /// laid tight; the bending stiffness and the sag of the runs take up a
    /// few mm, the contacts' compression the rest). A belt more than
    /// [`FIXED_CENTRE_SHORT_TOL_MM`] shorter than the path at that centre
    /// (the path of the belt laid tight, joints on the wheels' link
    /// polygons), one that does not settle there, or one pulling on the
    /// idler at rest with less than
    /// [`FIXED_CENTRE_MIN_PRETENSION_PER_WEIGHT`] × its weight (slack) is
    /// [`Error::FixedCentreBelt`]: how many mm too short or long, and where
    /// it is tight. The rig's [`RigConfig::idler_force_n`] is then the
    /// spring's force at rest (the pretension); [`Rig::idler_force_n`]
    /// gives it at the present state, and the rig test reports its mean.
    pub fn from_gear(
        model: Model<T>,
        gear: &RunningGear<T>,
        settings: Settings<T>,
    ) -> Result<Self> {
        gear.validate()?;
        if let Some(config) = gear.two_wheel_rig_config() {
            return Rig::new(model, config, settings);
        }
        // A fixed centre: the idler is held at its centre by a spring, no
        // force; the config's force (a placeholder until the belt has
        // settled) becomes the pretension.
        let (force_n, is_fixed) = match gear.tensioner {
            Tensioner::Force { force_n } => (force_n, false),
            Tensioner::FixedCentre => (T::ONE, true),
        };
        let min_pretension_n = (model.belt.mass_kg * model.gravity_m_s2).to_f64()
            * FIXED_CENTRE_MIN_PRETENSION_PER_WEIGHT;
        let (drive, idler) = match (gear.drive(), gear.idler()) {
            (Some(d), Some(i)) => (*d, *i),
            _ => return Err(invalid("running_gear.wheels", "needs a drive and an idler")),
        };
        let n = model.belt.links;
        let extra = usize::from(gear.ground.is_some());
        if n + 5 + extra > D {
            return Err(Error::Capacity {
                what: "running-gear unknowns (links + 5, + 1 with ground)",
                requested: n + 5 + extra,
                capacity: D,
            });
        }
        let (dx, dy) = (
            (idler.x_m - drive.x_m).to_f64(),
            (idler.y_m - drive.y_m).to_f64(),
        );
        let d0 = libm::hypot(dx, dy);
        let mut lay = GearLayout {
            x: [0.0; MAX_WHEELS],
            y: [0.0; MAX_WHEELS],
            diameter: [0.0; MAX_WHEELS],
            count: gear.wheels.len(),
            drive: 0,
            idler: 0,
            ux: dx / d0,
            uy: dy / d0,
            ground_n: None,
        };
        let half = T::from_f64(0.5);
        let mut fixed = [FixedWheel {
            x: T::ZERO,
            y: T::ZERO,
            r: T::ZERO,
        }; MAX_FIXED_WHEELS];
        let mut fixed_count = 0;
        for (k, w) in gear.wheels.iter().enumerate() {
            let (x, y) = (w.x_m - drive.x_m, w.y_m - drive.y_m);
            lay.x[k] = x.to_f64();
            lay.y[k] = y.to_f64();
            lay.diameter[k] = w.diameter_m.to_f64();
            match w.role {
                WheelRole::Drive => lay.drive = k,
                WheelRole::Idler => lay.idler = k,
                WheelRole::Road | WheelRole::Support => {
                    if let Some(slot) = fixed.get_mut(fixed_count) {
                        *slot = FixedWheel {
                            x,
                            y,
                            r: w.diameter_m * half,
                        };
                        fixed_count += 1;
                    }
                }
            }
        }
        let c = &gear.contact;
        let config = RigConfig {
            drive_diameter_m: drive.diameter_m,
            idler_diameter_m: idler.diameter_m,
            idler_force_n: force_n,
            idler_mass_kg: c.idler_mass_kg,
            idler_damping_n_s_per_m: c.idler_damping_n_s_per_m,
            wheel_stiffness_n_per_m: c.stiffness_n_per_m,
            wheel_damping_n_s_per_m: c.damping_n_s_per_m,
            drive_friction: c.drive_friction,
            slip_speed_m_s: c.slip_speed_m_s,
            bearing_friction_nm: gear.bearing_friction_nm,
        };
        config.validate()?;
        let g = model.gravity_m_s2;
        let mut chain = Chain::new(model, settings)?;
        chain.contacts.floor_enabled = false;
        chain.contacts.self_contact.enabled = false;
        let hold = is_fixed.then(|| {
            let k = FIXED_CENTRE_STIFFNESS_FACTOR * config.wheel_stiffness_n_per_m.to_f64();
            let m = config.idler_mass_kg.to_f64();
            CentreHold {
                centre_m: T::from_f64(d0),
                stiffness_n_per_m: T::from_f64(k),
                damping_n_s_per_m: T::from_f64(2.0 * libm::sqrt(k * m)),
            }
        });
        chain.idler = Some(IdlerAxle {
            mass_kg: config.idler_mass_kg,
            damping_n_s_per_m: config.idler_damping_n_s_per_m,
            force_n: if is_fixed {
                T::ZERO
            } else {
                config.idler_force_n
            },
            hold,
        });
        chain.contacts.wheels = Some(Wheels {
            drive_r: config.drive_diameter_m * half,
            idler_r: config.idler_diameter_m * half,
            idler_x: T::ZERO,
            idler_vx: T::ZERO,
            drive_omega: T::ZERO,
            stiffness: config.wheel_stiffness_n_per_m,
            damping: config.wheel_damping_n_s_per_m,
            friction: config.drive_friction,
            slip_speed: config.slip_speed_m_s,
            idler_ux: T::from_f64(lay.ux),
            idler_uy: T::from_f64(lay.uy),
            fixed,
            fixed_count,
        });
        if let Some(ground) = gear.ground {
            let weight = ground.load_kg * g;
            lay.ground_n = Some(weight.to_f64());
            // The robot's body: its mass moves with the ground (in the
            // track's frame), damped like the idler's slider.
            chain.ground = Some(GroundAxle {
                mass_kg: ground.load_kg,
                damping_n_s_per_m: config.idler_damping_n_s_per_m,
                force_n: weight,
            });
            chain.contacts.ground = Some(GroundContact {
                y: T::ZERO,
                vy: T::ZERO,
            });
        }
        let mut rig = Rig {
            chain,
            config,
            idler_offset_m: 0.0,
            layout: Layout::Gear(lay),
            ground_offset_m: 0.0,
            fixed_centre_m: is_fixed.then_some(d0),
        };
        if let Some(w) = lay.ground_n {
            // Start with the ground pressed in by about the load over the
            // contact stiffness.
            let k = config.wheel_stiffness_n_per_m.to_f64();
            rig.ground_offset_m = (w / k).min(1e-3);
        }
        let d = rig.lay_out(0.0)?;
        if is_fixed {
            // The belt laid out tight round the wheels (the idler at `d`,
            // every contact just touching): the belt must be long enough
            // for the path at the given centre; hold the idler there.
            let short = rig.path_excess_mm(&lay, d, d0);
            let belt_error = Error::FixedCentreBelt {
                short_by_mm: short,
                centre_distance_mm: d0 * 1e3,
                fits_at_mm: d * 1e3,
            };
            if short.is_nan() || short > FIXED_CENTRE_SHORT_TOL_MM {
                return Err(belt_error);
            }
            let i = rig.chain.idler_index();
            rig.chain.q[i] = T::from_f64(d0);
            rig.chain.reset_motion();
            // A belt that does not settle here is too short (the contacts
            // cannot take up the difference) or hangs slack: say by how
            // much.
            if rig.chain.solve_static().is_err() {
                return Err(belt_error);
            }
            let pretension = rig.idler_force_n();
            let pull = pretension.to_f64();
            if pull.is_nan() || pull < min_pretension_n {
                return Err(Error::FixedCentreBelt {
                    short_by_mm: short.min(-0.05),
                    centre_distance_mm: d0 * 1e3,
                    fits_at_mm: d * 1e3,
                });
            }
            rig.config.idler_force_n = pretension;
        } else {
            rig.chain.solve_static()?;
        }
        rig.idler_offset_m = rig.idler_position_m().to_f64() - d;
        if rig.chain.ground.is_some() {
            let gi = rig.chain.ground_index();
            rig.ground_offset_m =
                rig.chain.q[gi].to_f64() - rig.chain.kin.lowest_outer_y().to_f64();
        }
        Ok(rig)
    }

    /// How much longer the path round the wheels is with the idler at `d0`
    /// than at `d` (where the belt just fits), mm: how much too short the
    /// belt is for a fixed centre at `d0` (negative: too long). The paths
    /// are the hulls of the joint polygons (the lay-out's).
    fn path_excess_mm(&self, g: &GearLayout, d: f64, d0: f64) -> f64 {
        match (self.gear_hull(g, d0), self.gear_hull(g, d)) {
            (Some(a), Some(b)) => (a.total - b.total) * 1e3,
            // No hull at the given centre: the idler is inside the others.
            _ => -((d - d0).abs() * 2e3),
        }
    }

    /// The tensioner's force on the idler's axle along its slide, N: the
    /// constant force, or for a fixed centre the holding spring's force at
    /// the present state (the belt's pull on the idler).
    pub fn idler_force_n(&self) -> T {
        match self.chain.idler.and_then(|ax| ax.hold) {
            Some(h) => {
                let i = self.chain.idler_index();
                h.force_n(self.chain.q[i], self.chain.v[i])
            }
            None => self.config.idler_force_n,
        }
    }

    /// The idler's fixed centre distance from the drive, m (`None`: a
    /// force tensioner).
    pub fn fixed_centre_m(&self) -> Option<T> {
        self.fixed_centre_m.map(T::from_f64)
    }

    /// Lay the belt round the wheels (joints on the polygon circumscribing
    /// each wheel, straight runs between), shifted along its path by
    /// `phase` link lengths, at rest; the axle distance is chosen so that
    /// the chain closes. Returns that distance (m); the idler axle starts
    /// there plus the compression found when the rig first settled.
    pub(crate) fn lay_out(&mut self, phase: f64) -> Result<f64> {
        let l = self.chain.l.to_f64();
        match self.layout {
            Layout::TwoWheel => self.lay_out_from(|_| phase * l),
            Layout::Gear(g) => self.lay_out_gear(&g, |_| phase * l),
        }
    }

    /// Lay the belt out as [`Rig::lay_out`] does, with joint 0 on the drive
    /// wheel at the polar angle `phi_rad` (−π: the leftmost point, the
    /// middle of the wrap).
    pub(crate) fn lay_out_on_drive(&mut self, phi_rad: f64) -> Result<f64> {
        match self.layout {
            Layout::TwoWheel => self.lay_out_from(|p| p.drive_start_s() + (-p.a - phi_rad) * p.r1),
            Layout::Gear(g) => self.lay_out_gear(&g, |h| (h.a_in[0] - phi_rad) * h.rho[0]),
        }
    }

    /// Polar angle on the drive wheel where the belt arrives on it, rad:
    /// −π/2 on the paper's rig (the estimator's convention there), the
    /// hull's entry angle on a running gear.
    pub(crate) fn drive_entry_rad(&self) -> f64 {
        match self.layout {
            Layout::TwoWheel => -core::f64::consts::FRAC_PI_2,
            Layout::Gear(g) => self
                .gear_hull(&g, self.idler_position_m().to_f64())
                .map_or(-core::f64::consts::FRAC_PI_2, |h| h.a_in[0]),
        }
    }

    /// Angle of the drive wheel the belt wraps, rad (π for equal wheels).
    pub(crate) fn drive_wrap_rad(&self) -> f64 {
        if let Layout::Gear(g) = self.layout {
            return self
                .gear_hull(&g, self.idler_position_m().to_f64())
                .map_or(0.0, |h| h.sweep[0]);
        }
        let r1 = 0.5 * self.config.drive_diameter_m.to_f64();
        let r2 = 0.5 * self.config.idler_diameter_m.to_f64();
        let d = self.idler_position_m().to_f64().max(1e-9);
        let nx = ((r1 - r2) / d).clamp(-0.99, 0.99);
        2.0 * core::f64::consts::PI - 2.0 * libm::atan2(libm::sqrt(1.0 - nx * nx), nx)
    }

    /// Joint radius on the drive wheel, m, and the angle one wrapped link
    /// subtends there, rad.
    pub(crate) fn drive_polygon(&self) -> (f64, f64) {
        self.wrap_polygon(self.config.drive_diameter_m)
    }

    /// A wheel of `diameter_m` wrapped by the belt's links: the polygon the
    /// joints make when every link's inner edge touches the rim. Returns
    /// the joint radius (m) and the angle one link subtends (rad).
    fn wrap_polygon(&self, diameter_m: T) -> (f64, f64) {
        self.wrap_polygon_f64(diameter_m.to_f64())
    }

    fn wrap_polygon_f64(&self, diameter_m: f64) -> (f64, f64) {
        let l = self.chain.l.to_f64();
        let rho = 0.5 * diameter_m + self.chain.half_t.to_f64();
        let beta = 2.0 * libm::atan(l / (2.0 * rho));
        (rho / libm::cos(0.5 * beta), beta)
    }

    /// The hull of a running gear's wheels with the idler at distance `d`
    /// from the drive (joint-polygon radii).
    fn gear_hull(&self, g: &GearLayout, d: f64) -> Option<Hull> {
        let mut c = [(0.0f64, 0.0f64, 0.0f64); MAX_WHEELS];
        for (k, slot) in c.iter_mut().enumerate().take(g.count) {
            let (x, y) = if k == g.idler {
                (g.ux * d, g.uy * d)
            } else {
                (g.x[k], g.y[k])
            };
            *slot = (x, y, self.wrap_polygon_f64(g.diameter[k]).0);
        }
        Hull::new(&c[..g.count], g.drive)
    }

    fn lay_out_gear<F: Fn(&Hull) -> f64>(&mut self, g: &GearLayout, start: F) -> Result<f64> {
        let belt = self.chain.l.to_f64() * self.chain.n as f64;
        // The idler's axle distance closing the belt: between where the
        // wheels first make a hull and half the belt.
        let hi = belt / 2.0;
        let mut lo = 1e-3;
        while lo < hi && self.gear_hull(g, lo).is_none() {
            lo += (hi - lo) / 64.0 + 1e-4;
        }
        let (n, l) = (self.chain.n, self.chain.l.to_f64());
        let me = &*self;
        let d = bisect_closure::<Hull, D, _, _>(
            n,
            l,
            lo,
            hi,
            |d| me.gear_hull(g, d),
            &start,
            "running_gear.wheels",
        )?;
        let hull = self.gear_hull(g, d).ok_or(Error::Singular)?;
        self.place(&hull, start(&hull), d);
        if self.chain.ground.is_some() {
            let gi = self.chain.ground_index();
            let lowest = self.chain.kin.lowest_outer_y().to_f64();
            self.chain.q[gi] = T::from_f64(lowest + self.ground_offset_m);
            self.chain.reset_motion();
        }
        Ok(d)
    }

    fn lay_out_from<F: Fn(&Path) -> f64>(&mut self, start: F) -> Result<f64> {
        let (r1, _) = self.wrap_polygon(self.config.drive_diameter_m);
        let (r2, _) = self.wrap_polygon(self.config.idler_diameter_m);
        let n = self.chain.n;
        let l = self.chain.l.to_f64();
        let belt = l * n as f64;
        // Bisection on the axle distance: the N chords must close the path.
        let (lo, hi) = ((r1 - r2).abs() * 1.02 + 1e-3, belt / 2.0);
        let d = bisect_closure::<Path, D, _, _>(
            n,
            l,
            lo,
            hi,
            |d| Path::new(r1, r2, d),
            &start,
            "rig.drive_diameter_m/idler_diameter_m",
        )?;
        let path = Path::new(r1, r2, d).ok_or(Error::Singular)?;
        self.place(&path, start(&path), d);
        Ok(d)
    }

    /// Put the joints on `path` from arc length `s0` (N chords) at rest, the
    /// idler's axle at `d` plus the settled offset.
    fn place<L: Loop>(&mut self, path: &L, s0: f64, d: f64) {
        let c = &mut self.chain;
        let n = c.n;
        let l = c.l.to_f64();
        let mut s = [0.0f64; D];
        path.walk(n, l, s0, &mut s);
        let mut prev_theta = 0.0f64;
        let mut first = path.point(s[0]);
        c.q = [T::ZERO; D];
        c.q[X] = T::from_f64(first.0);
        c.q[Y] = T::from_f64(first.1);
        for k in 0..n {
            let next = path.point(s[k + 1]);
            let raw = libm::atan2(next.1 - first.1, next.0 - first.0);
            let mut dt = raw - prev_theta;
            while dt > core::f64::consts::PI {
                dt -= core::f64::consts::TAU;
            }
            while dt <= -core::f64::consts::PI {
                dt += core::f64::consts::TAU;
            }
            let theta = if k == 0 { raw } else { prev_theta + dt };
            c.q[TH + k] = T::from_f64(theta);
            prev_theta = theta;
            first = next;
        }
        c.q[TH + n] = T::from_f64(d + self.idler_offset_m);
        c.lam = [T::ZERO; 2];
        c.reset_motion();
    }

    /// The chain (joint angles, positions, solver counters).
    pub fn chain(&self) -> &Chain<T, D> {
        &self.chain
    }

    /// The rig's parameters.
    pub fn config(&self) -> &RigConfig<T> {
        &self.config
    }

    /// Set the drive wheel's speed (clockwise positive), rad/s. The speed
    /// is prescribed: the drive supplies whatever torque it takes.
    pub fn set_drive_speed(&mut self, omega_rad_s: T) -> Result<()> {
        if !omega_rad_s.is_finite() {
            return Err(Error::NonFinite {
                what: "drive speed",
            });
        }
        if let Some(w) = self.chain.contacts.wheels.as_mut() {
            w.drive_omega = omega_rad_s;
        }
        Ok(())
    }

    /// The drive wheel's speed, rad/s.
    pub fn drive_speed_rad_s(&self) -> T {
        self.chain
            .contacts
            .wheels
            .map_or(T::ZERO, |w| w.drive_omega)
    }

    /// Position of the idler axle (distance from the drive axle), m.
    pub fn idler_position_m(&self) -> T {
        self.chain.q[self.chain.idler_index()]
    }

    /// The ground's height under a running gear, m (`None` without ground).
    pub fn ground_height_m(&self) -> Option<T> {
        self.chain
            .ground
            .map(|_| self.chain.q[self.chain.ground_index()])
    }

    /// The force the ground carries at the present state, N (the sum of its
    /// contact forces; at rest, the robot's weight on this track). Zero
    /// without ground.
    pub fn ground_force_n(&self) -> T {
        let mut f = T::ZERO;
        self.chain
            .contacts
            .for_each_contact(&self.chain.kin, false, |_, ct| {
                if ct.kind == ContactKind::Ground {
                    f += ct.force.1;
                }
            });
        f
    }

    /// Whether the ground presses the belt onto the drive wheel at the
    /// present state: the links touching both carry at least 1 % of the
    /// ground's force (a gear whose load rests on the drive, as when the
    /// drive is the lowest wheel). The estimator then keeps the drive's
    /// friction in its dynamics.
    pub(crate) fn ground_presses_drive(&self) -> bool {
        let c = &self.chain;
        if c.ground.is_none() {
            return false;
        }
        let mut on_drive = [false; D];
        c.contacts.for_each_contact(&c.kin, false, |_, ct| {
            if ct.kind == ContactKind::Drive {
                if let Some(slot) = on_drive.get_mut(ct.a.link) {
                    *slot = true;
                }
            }
        });
        let (mut pinched, mut total) = (T::ZERO, T::ZERO);
        c.contacts.for_each_contact(&c.kin, false, |_, ct| {
            if ct.kind == ContactKind::Ground {
                total += ct.force.1;
                if on_drive.get(ct.a.link).copied().unwrap_or(false) {
                    pinched += ct.force.1;
                }
            }
        });
        total > T::ZERO && pinched >= T::from_f64(0.01) * total
    }

    /// Torque the drive applies to the belt (clockwise positive), N·m: the
    /// moment of the belt–drive contact forces about the axle plus the
    /// bearing friction.
    pub fn drive_torque_nm(&self) -> T {
        let mut tau = drive_contact_torque(&self.chain);
        let w = self.drive_speed_rad_s();
        let b = self.config.bearing_friction_nm;
        if b > T::ZERO {
            // Coulomb bearing friction, regularised over ±0.01 rad/s.
            let eps = T::from_f64(0.01);
            tau += b * (w / eps).clamp(-T::ONE, T::ONE);
        }
        tau
    }

    /// Belt path speed per unit drive speed, m/rad: a link advances by one
    /// link length while the drive turns by the angle a wrapped link
    /// subtends.
    pub fn path_speed_per_rad_m(&self) -> T {
        let (_, beta) = self.drive_polygon();
        T::from_f64(self.chain.l.to_f64() / beta)
    }

    /// Simulated time, s.
    pub fn time_s(&self) -> T {
        self.chain.time_s()
    }

    /// Advance by one step of at most `h_max` s at the current drive speed.
    pub fn step_max(&mut self, h_max: T) -> Result<()> {
        self.chain.step_max(h_max)
    }

    /// Set the belt temperature used by `thermal_softening`, °C (see
    /// [`Chain::set_belt_temperature_c`]).
    pub fn set_belt_temperature_c(&mut self, temp_c: T) -> Result<()> {
        self.chain.set_belt_temperature_c(temp_c)
    }

    /// Mutable access for the estimator's travelling-belt statics.
    pub(crate) fn chain_mut(&mut self) -> &mut Chain<T, D> {
        &mut self.chain
    }
}

/// Bisection on the idler's axle distance in `[lo, hi]`: the `n` chords of
/// length `l` walked from `start` must close the path `make(d)`.
fn bisect_closure<L: Loop, const D: usize, M: Fn(f64) -> Option<L>, S: Fn(&L) -> f64>(
    n: usize,
    l: f64,
    lo: f64,
    hi: f64,
    make: M,
    start: &S,
    what: &'static str,
) -> Result<f64> {
    let (mut lo, mut hi) = (lo, hi);
    let mut s = [0.0f64; D];
    let gap = |d: f64, s: &mut [f64; D]| -> Option<f64> {
        let p = make(d)?;
        let s0 = start(&p);
        Some(p.walk(n, l, s0, s) - s0 - p.len())
    };
    match (gap(lo, &mut s), gap(hi, &mut s)) {
        (Some(a), Some(b)) if a > 0.0 && b < 0.0 => {}
        _ => {
            return Err(invalid(
                what,
                "the belt is too short or too long to wrap these wheels",
            ))
        }
    }
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        match gap(mid, &mut s) {
            Some(g) if g > 0.0 => lo = mid,
            Some(_) => hi = mid,
            None => return Err(Error::Singular),
        }
    }
    Ok(0.5 * (lo + hi))
}

/// Moment about the drive axle of the belt–drive contact forces (clockwise
/// positive), at the chain's present positions and velocities, N·m.
pub(crate) fn drive_contact_torque<T: Real, const D: usize>(chain: &Chain<T, D>) -> T {
    let mut tau = T::ZERO;
    chain.contacts.for_each_contact(&chain.kin, true, |ch, ct| {
        if ct.kind == ContactKind::Drive {
            let (x, y) = ch.point_position(ct.a);
            // Counter-clockwise moment of the force on the belt, negated.
            tau -= x * ct.force.1 - y * ct.force.0;
        }
    });
    tau
}

/// The rig test: ramp the drive from rest to a speed, hold it, and average
/// the torque once it has settled.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigTest {
    /// Final drive speed, rad/s (the paper: 5).
    pub speed_rad_s: f64,
    /// Duration of the linear ramp from rest, s (the paper: 1).
    pub ramp_s: f64,
    /// Time held at the final speed, s.
    pub hold_s: f64,
    /// Time after the ramp before the average starts, s.
    pub settle_s: f64,
}

impl Default for RigTest {
    fn default() -> Self {
        RigTest {
            speed_rad_s: 5.0,
            ramp_s: 1.0,
            hold_s: 2.0,
            settle_s: 0.5,
        }
    }
}

/// One sample of the rig test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigSample {
    /// Time, s.
    pub time_s: f64,
    /// Drive speed, rad/s.
    pub speed_rad_s: f64,
    /// Drive torque, N·m.
    pub torque_nm: f64,
    /// The part of it the joints' damping dissipates (bending loss power
    /// over drive speed), N·m.
    pub bending_torque_nm: f64,
    /// Kinetic energy of the belt (and idler slider), J: its rate over the
    /// drive speed is the torque that accelerates the belt.
    pub kinetic_energy_j: f64,
}

/// The rig test's figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigFigures {
    /// Time-averaged drive torque over the constant-speed phase, N·m.
    pub torque_nm_mean: f64,
    /// Its standard deviation (the link-passing ripple), N·m.
    pub torque_nm_std: f64,
    /// Mean power the joints' damping dissipates over the same phase,
    /// divided by the drive speed: the bending resistance proper, N·m. The
    /// rest of the drive torque is lost in the belt–wheel contacts and the
    /// tensioner's slider.
    pub bending_torque_nm_mean: f64,
    /// Drive speed of the constant phase, rad/s.
    pub speed_rad_s: f64,
    /// Tensioner force, N (a fixed idler centre: the holding spring's
    /// force averaged over the same phase, the belt's pull on the idler).
    pub idler_force_n: f64,
    /// Axle distance at the end, mm.
    pub axle_distance_mm: f64,
    /// Force the ground carries, averaged over the same phase, N (a running
    /// gear with ground; 0 without).
    pub ground_force_n_mean: f64,
}

/// Drive speed of the rig test's profile at time `t_s`.
pub fn ramp_speed(test: &RigTest, t_s: f64) -> f64 {
    if test.ramp_s <= 0.0 {
        return test.speed_rad_s;
    }
    test.speed_rad_s * (t_s / test.ramp_s).clamp(0.0, 1.0)
}

/// Run the rig test from the settled rig; `observe` sees every accepted step.
pub fn rig_test<T: Real, const D: usize, F: FnMut(RigSample)>(
    rig: &mut Rig<T, D>,
    test: &RigTest,
    mut observe: F,
) -> Result<RigFigures> {
    let ok = |x: f64| x.is_finite() && x >= 0.0;
    if !test.speed_rad_s.is_finite() || !ok(test.ramp_s) || !ok(test.settle_s) {
        return Err(invalid(
            "rig test",
            "speed, ramp and settle times must be finite (times not negative)",
        ));
    }
    if !(test.hold_s.is_finite() && test.hold_s > test.settle_s)
        || test.ramp_s + test.hold_s > 600.0
    {
        return Err(invalid(
            "rig test.hold_s",
            "must exceed settle_s and the whole test stay under 600 s",
        ));
    }
    rig.chain.set_time(T::ZERO);
    rig.chain.reset_motion();
    let end = test.ramp_s + test.hold_s;
    let from = test.ramp_s + test.settle_s;
    let h = rig.chain.settings.step_s.to_f64();
    let (mut sum, mut sum2, mut span, mut bend) = (0.0, 0.0, 0.0, 0.0);
    // A fixed idler centre: the holding spring's force, averaged.
    let fixed = rig.fixed_centre_m.is_some();
    let mut idler_sum = 0.0;
    let ground = rig.chain.ground.is_some();
    let mut ground_sum = 0.0;
    let mut t_prev = 0.0;
    let min_step = rig.chain.settings.min_step_s.to_f64();
    step_until(
        rig,
        end,
        min_step,
        "rig test (too many steps)",
        |rig| rig.time_s().to_f64(),
        |rig, t| {
            let dt = h.min(end - t);
            // Speed at the end of the step (implicit scheme).
            rig.set_drive_speed(T::from_f64(ramp_speed(test, t + dt)))?;
            rig.step_max(T::from_f64(dt))?;
            let t_now = rig.time_s().to_f64();
            let tau = rig.drive_torque_nm().to_f64();
            if !tau.is_finite() {
                return Err(Error::Diverged {
                    time_s: t_now,
                    reason: "drive torque became non-finite",
                });
            }
            let omega = rig.drive_speed_rad_s().to_f64();
            let bend_p = rig.chain.joint_damping_power_w().to_f64();
            observe(RigSample {
                time_s: t_now,
                speed_rad_s: omega,
                torque_nm: tau,
                bending_torque_nm: if omega.abs() > 1e-9 {
                    bend_p / omega
                } else {
                    0.0
                },
                kinetic_energy_j: rig.chain.kinetic_energy_j().to_f64(),
            });
            if t_now > from {
                let w = t_now - t_prev.max(from);
                sum += tau * w;
                sum2 += tau * tau * w;
                bend += bend_p * w;
                span += w;
                if fixed {
                    idler_sum += rig.idler_force_n().to_f64() * w;
                }
                if ground {
                    ground_sum += rig.ground_force_n().to_f64() * w;
                }
            }
            t_prev = t_now;
            Ok(())
        },
    )?;
    let mean = if span > 0.0 { sum / span } else { 0.0 };
    let var = if span > 0.0 {
        (sum2 / span - mean * mean).max(0.0)
    } else {
        0.0
    };
    Ok(RigFigures {
        torque_nm_mean: mean,
        torque_nm_std: libm::sqrt(var),
        bending_torque_nm_mean: if span > 0.0 && test.speed_rad_s.abs() > 1e-9 {
            bend / span / test.speed_rad_s
        } else {
            0.0
        },
        speed_rad_s: test.speed_rad_s,
        idler_force_n: if fixed && span > 0.0 {
            idler_sum / span
        } else if fixed {
            rig.idler_force_n().to_f64()
        } else {
            rig.config.idler_force_n.to_f64()
        },
        axle_distance_mm: rig.idler_position_m().to_f64() * 1e3,
        ground_force_n_mean: if span > 0.0 { ground_sum / span } else { 0.0 },
    })
}

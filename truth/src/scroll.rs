//! The bending-resistance rig: the belt round a drive wheel (axle fixed,
//! speed prescribed) and an idler on a slider pulled away by a tensioner,
//! no ground. The drive torque is what the belt's contact forces need.

use crate::chain::{Chain, V2};
use crate::law::Material;
use crate::Error;

/// Gravity, m/s² (the rig stands in a vertical plane).
const G: f64 = 9.81;

/// Friction torque of an axle bearing: `T·tanh(ω/ω0)·(1 + v·|ω|)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bearing {
    /// Breakaway torque, N·m.
    pub torque_nm: f64,
    /// Regularising speed, rad/s.
    pub omega_reg: f64,
    /// Small speed-dependent part, per rad/s.
    pub viscous_per_rad_s: f64,
    /// On the idler's axle (else on the drive's).
    pub on_idler: bool,
}

impl Bearing {
    /// Resisting torque at speed `w`, N·m (opposes `w`).
    pub fn torque(&self, w: f64) -> f64 {
        self.torque_nm * (w / self.omega_reg).tanh() * (1.0 + self.viscous_per_rad_s * w.abs())
    }
}

/// A rig configuration.
#[derive(Debug, Clone)]
pub struct RigConfig {
    /// Belt length, m.
    pub length_m: f64,
    /// Belt thickness, m.
    pub thickness_m: f64,
    /// Belt mass, kg.
    pub mass_kg: f64,
    /// Nodes.
    pub nodes: usize,
    /// Axial stiffness EA, N.
    pub ea_n: f64,
    /// Bending behaviour.
    pub material: Material,
    /// Per-node factor of the elastic law.
    pub ei_scale: Vec<f64>,
    /// Drive wheel diameter, m.
    pub drive_d_m: f64,
    /// Idler diameter, m.
    pub idler_d_m: f64,
    /// Tensioner force on the idler's axle, N.
    pub idler_force_n: f64,
    /// Bearing friction, if any.
    pub bearing: Option<Bearing>,
    /// Eccentricity of the idler's running surface, m (0: none).
    pub idler_runout_m: f64,
    /// Belt–wheel friction coefficient.
    pub mu: f64,
    /// Intervals (start s, end s) where the drive's friction falls to
    /// `mu_slip` (a wet or greasy patch).
    pub slip_windows: Vec<(f64, f64)>,
    /// Friction coefficient inside the slip windows.
    pub mu_slip: f64,
}

/// The drive speed against time.
pub trait Profile {
    /// Drive speed at `t`, rad/s.
    fn omega(&self, t: f64) -> f64;
    /// Belt temperature rise at `t`, K.
    fn temp_rise(&self, t: f64) -> f64;
}

/// What the rig recorded, one row per `record_s`.
#[derive(Debug, Clone, Default)]
pub struct RigRun {
    /// Times, s.
    pub t_s: Vec<f64>,
    /// Drive speed (mean over the interval), rad/s.
    pub omega_rad_s: Vec<f64>,
    /// Drive torque (mean over the interval), N·m.
    pub torque_nm: Vec<f64>,
    /// Idler axle position at the end, m.
    pub center_distance_m: f64,
    /// Step used, s.
    pub step_s: f64,
}

/// Centre distance for a belt path of length `l` round pitch radii r1, r2.
pub fn center_distance(l: f64, r1: f64, r2: f64) -> Option<f64> {
    let len = |c: f64| {
        let g = ((r1 - r2) / c).asin();
        r1 * (std::f64::consts::PI + 2.0 * g)
            + r2 * (std::f64::consts::PI - 2.0 * g)
            + 2.0 * c * g.cos()
    };
    let mut lo = (r1 - r2).abs() + 1e-6;
    let mut hi = l;
    if len(lo) > l || len(hi) < l {
        return None;
    }
    for _ in 0..100 {
        let m = 0.5 * (lo + hi);
        if len(m) < l {
            lo = m;
        } else {
            hi = m;
        }
    }
    Some(0.5 * (lo + hi))
}

/// Points along the open-belt path (counter-clockwise), `n` of them.
fn path(n: usize, r1: f64, r2: f64, c: f64) -> Vec<V2> {
    let g = ((r1 - r2) / c).asin();
    let a = std::f64::consts::FRAC_PI_2 - g; // upper tangent points' angle
    let span = c * g.cos();
    let arc2 = r2 * 2.0 * a;
    let arc1 = r1 * (std::f64::consts::TAU - 2.0 * a);
    let total = 2.0 * span + arc1 + arc2;
    let p1 = |phi: f64| [r1 * phi.cos(), r1 * phi.sin()];
    let p2 = |phi: f64| [c + r2 * phi.cos(), r2 * phi.sin()];
    (0..n)
        .map(|i| {
            let mut s = total * i as f64 / n as f64;
            // Lower span, from drive (angle −a) to idler (angle −a).
            let q0 = p1(-a);
            let q1 = p2(-a);
            if s < span {
                let u = s / span;
                return [q0[0] + u * (q1[0] - q0[0]), q0[1] + u * (q1[1] - q0[1])];
            }
            s -= span;
            if s < arc2 {
                return p2(-a + s / r2);
            }
            s -= arc2;
            let q2 = p2(a);
            let q3 = p1(a);
            if s < span {
                let u = s / span;
                return [q2[0] + u * (q3[0] - q2[0]), q2[1] + u * (q3[1] - q2[1])];
            }
            s -= span;
            p1(a + s / r1)
        })
        .collect()
}

struct Wheel {
    axle: V2,
    radius: f64,
    omega: f64,
    angle: f64,
    runout: f64,
}

impl RigConfig {
    /// Run the rig: settle at rest, then follow `profile` for `duration_s`.
    pub fn run(
        &self,
        profile: &dyn Profile,
        duration_s: f64,
        record_s: f64,
    ) -> Result<RigRun, Error> {
        let n = self.nodes;
        if n < 8 || self.ei_scale.len() != n {
            return Err(Error::Invalid(format!("node count {n}")));
        }
        let ht = 0.5 * self.thickness_m;
        let r1 = 0.5 * self.drive_d_m;
        let r2 = 0.5 * self.idler_d_m;
        let c = center_distance(self.length_m, r1 + ht, r2 + ht)
            .ok_or_else(|| Error::Invalid("belt too short for the wheels".into()))?;
        let x = path(n, r1 + ht, r2 + ht, c);
        let mut chain = Chain::new(
            x,
            self.length_m / n as f64,
            ht,
            self.mass_kg,
            self.ea_n,
            self.ei_scale.clone(),
        );
        let mat = self.material;
        let mut drive = Wheel {
            axle: [0.0, 0.0],
            radius: r1,
            omega: 0.0,
            angle: 0.0,
            runout: 0.0,
        };
        let mut idler = Wheel {
            axle: [c, 0.0],
            radius: r2,
            omega: 0.0,
            angle: 0.0,
            runout: self.idler_runout_m,
        };
        let idler_j = 0.5 * 2.0 * r2 * r2; // a 2 kg disc
        let slider_kg = 3.0;
        let mut slider_v = 0.0;
        // Contact: linear penalty per node sized so the wrap load
        // (tension/radius per metre) sinks a node by about 0.1 mm.
        let wrap_load = 0.5 * self.idler_force_n / r1.min(r2) * chain.l0;
        let k_w = (wrap_load / 1e-4).max(2e5);
        let c_w = 0.2 * (k_w * chain.node_mass).sqrt();
        let v_reg = 0.2;
        let mu_max = self.mu.max(self.mu_slip);
        let b = mat.elastic.max_tangent() * self.ei_scale.iter().fold(1.0, |a, &b| f64::max(a, b));
        let mut cm = mat.damping.max_slope();
        if let crate::law::FrictionLaw::Tanh { m_c, rate } = mat.friction {
            cm += m_c / rate;
        }
        let h = chain.stable_step(b, cm, k_w, c_w + mu_max * wrap_load / v_reg, 0.6);
        let settle_s = 0.8;
        let settle_steps = (settle_s / h).ceil() as usize;
        let steps = (duration_s / h).ceil() as usize;
        let every = ((record_s / h).round() as usize).max(1);
        let mut run = RigRun {
            step_s: h,
            ..Default::default()
        };
        let (mut acc_w, mut acc_t, mut acc_n) = (0.0, 0.0, 0usize);
        for s in 0..settle_steps + steps {
            let settling = s < settle_steps;
            let t = if settling {
                0.0
            } else {
                (s - settle_steps) as f64 * h
            };
            let (sf, df) = match mat.thermal {
                Some(th) if !settling => th.factors(profile.temp_rise(t)),
                _ => (1.0, 1.0),
            };
            drive.omega = if settling { 0.0 } else { profile.omega(t) };
            let mu_drive = if !settling && self.slip_windows.iter().any(|&(a, b)| t >= a && t < b) {
                self.mu_slip
            } else {
                self.mu
            };
            chain.internal_forces(&mat, sf, df);
            chain.gravity(G);
            if settling {
                chain.settling_drag(20.0);
            }
            let mut drive_torque = 0.0;
            let mut idler_torque = 0.0;
            let mut idler_fx = 0.0;
            for i in 0..n {
                for (w, wheel) in [&drive, &idler].into_iter().enumerate() {
                    // Running surface's centre (an eccentric idler wobbles).
                    let cen = [
                        wheel.axle[0] + wheel.runout * wheel.angle.cos(),
                        wheel.axle[1] + wheel.runout * wheel.angle.sin(),
                    ];
                    let d = [chain.x[i][0] - cen[0], chain.x[i][1] - cen[1]];
                    let dist = (d[0] * d[0] + d[1] * d[1]).sqrt();
                    let pen = wheel.radius + ht - dist;
                    if pen <= 0.0 || dist < 1e-9 {
                        continue;
                    }
                    let nn = [d[0] / dist, d[1] / dist];
                    let tt = [-nn[1], nn[0]];
                    // Velocity of the wheel material under the node.
                    let r_ax = [chain.x[i][0] - wheel.axle[0], chain.x[i][1] - wheel.axle[1]];
                    let vw = [-wheel.omega * r_ax[1], wheel.omega * r_ax[0]];
                    let vs = if w == 1 { [slider_v, 0.0] } else { [0.0, 0.0] };
                    let rel = [chain.v[i][0] - vw[0] - vs[0], chain.v[i][1] - vw[1] - vs[1]];
                    let pen_dot = -(rel[0] * nn[0] + rel[1] * nn[1]);
                    let fnm = (k_w * pen + c_w * pen_dot).max(0.0);
                    let mu = if w == 0 { mu_drive } else { self.mu };
                    let slip = rel[0] * tt[0] + rel[1] * tt[1];
                    let ft = -mu * fnm * (slip / v_reg).tanh();
                    let fb = [fnm * nn[0] + ft * tt[0], fnm * nn[1] + ft * tt[1]];
                    chain.f[i][0] += fb[0];
                    chain.f[i][1] += fb[1];
                    // Reaction on the wheel, about its axle, at the contact point.
                    let pc = [
                        cen[0] + nn[0] * wheel.radius - wheel.axle[0],
                        cen[1] + nn[1] * wheel.radius - wheel.axle[1],
                    ];
                    let tq = -(pc[0] * fb[1] - pc[1] * fb[0]);
                    if w == 0 {
                        drive_torque += tq;
                    } else {
                        idler_torque += tq;
                        idler_fx -= fb[0];
                    }
                }
            }
            // Motor torque: balance the belt's torque on the drive, plus a
            // bearing on the drive's axle.
            let mut motor = -drive_torque;
            if let Some(bg) = self.bearing {
                if bg.on_idler {
                    idler_torque -= bg.torque(idler.omega);
                } else {
                    motor += bg.torque(drive.omega);
                }
            }
            chain.advance(h);
            chain.update_states(&mat, h);
            let slider_drag = if settling { 400.0 } else { 150.0 };
            slider_v += h * (self.idler_force_n + idler_fx - slider_drag * slider_v) / slider_kg;
            idler.axle[0] += h * slider_v;
            let idler_drag = if settling { 5.0 } else { 0.0 };
            idler.omega += h * (idler_torque - idler_drag * idler.omega) / idler_j;
            idler.angle += h * idler.omega;
            drive.angle += h * drive.omega;
            if !settling {
                acc_w += drive.omega;
                acc_t += motor;
                acc_n += 1;
                if acc_n == every {
                    run.t_s.push(t + h);
                    run.omega_rad_s.push(acc_w / acc_n as f64);
                    run.torque_nm.push(acc_t / acc_n as f64);
                    acc_w = 0.0;
                    acc_t = 0.0;
                    acc_n = 0;
                    if !chain.is_finite() || !motor.is_finite() {
                        return Err(Error::Unstable {
                            what: "rig",
                            t_s: t,
                        });
                    }
                }
            } else if s % 1000 == 0 && !chain.is_finite() {
                return Err(Error::Unstable {
                    what: "rig settling",
                    t_s: s as f64 * h,
                });
            }
        }
        run.center_distance_m = idler.axle[0];
        Ok(run)
    }
}

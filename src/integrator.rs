//! Time integration and static equilibrium.
//!
//! * [`Chain::step`]: variable-step **BDF2** (second order, L-stable, no
//!   numerical damping worth the name at 1–2 ms; BDF1 adds enough to inflate
//!   Λ) on the index-3 equations of motion, solved by simplified Newton: the
//!   Jacobian is refactored only when convergence slows. A step whose Newton
//!   iteration fails with a fresh Jacobian is rejected and retried at a
//!   quarter of the size; below `min_step_s` the run is a typed
//!   [`Error::Diverged`].
//! * [`Chain::solve_static`]: the equilibrium the belt settles to, found by a
//!   proximal-point iteration (implicit Euler with the velocity reset each
//!   step, the time scale growing geometrically), each step solved by Newton
//!   with the tangent stiffness — a few dozen factorisations instead of
//!   seconds of simulated settling.

use crate::chain::Chain;
use crate::error::{Error, Result};
use crate::real::Real;

/// How a Newton solve ended.
enum Newton {
    Converged { iterations: usize, rate: f64 },
    Failed,
}

impl<T: Real, const D: usize> Chain<T, D> {
    /// Weighted max-norm of a correction: 1 means "at the tolerance".
    fn correction_norm(&self, dz: &[T; D]) -> f64 {
        let nd = self.ndof();
        let eps = T::epsilon().to_f64() * 64.0;
        let pt = self.settings.position_tol_m.to_f64().max(eps);
        let at = self.settings.angle_tol_rad.to_f64();
        let mut worst = 0.0f64;
        for (i, d) in dz.iter().enumerate().take(nd) {
            let d = d.to_f64().abs();
            let tol = if self.is_length_coord(i) {
                pt
            } else {
                // f32 cannot resolve 1e-8 rad on angles of a few radians.
                at.max(eps * (1.0 + self.q[i].to_f64().abs()))
            };
            worst = worst.max(d / tol);
        }
        worst
    }

    /// Newton iteration from `z` (updated in place).
    fn newton(&mut self, z: &mut [T; D], full: bool) -> Newton {
        let ns = self.nsys();
        let mut r = [T::ZERO; D];
        let mut prev = f64::INFINITY;
        let mut rate = 0.0;
        for it in 0..self.settings.newton_iterations {
            self.residual(z, &mut r);
            if !r[..ns].iter().all(|x| x.is_finite()) {
                return Newton::Failed;
            }
            if full && it > 0 && self.assemble_jacobian(z).is_err() {
                return Newton::Failed;
            }
            for x in r.iter_mut().take(ns) {
                *x = -*x;
            }
            self.jac.solve(&mut r[..ns]);
            for i in 0..ns {
                z[i] += r[i];
            }
            let norm = self.correction_norm(&r);
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
    fn set_bdf(&mut self, h: T) {
        let nd = self.ndof();
        let (a0, a1, a2) = if self.history {
            let w = h / self.h_old;
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
        self.alpha_v = a0;
        self.alpha_a = a0 * a0;
        for i in 0..nd {
            let bv = a1 * self.q[i] + a2 * self.q_old[i];
            self.bv[i] = bv;
            self.ba[i] = a0 * bv + a1 * self.v[i] + a2 * self.v_old[i];
        }
    }

    /// The Jacobian is current for the present coefficients.
    fn jacobian_current(&self) -> bool {
        self.jac.is_factored()
            && self.jac.n == self.nsys()
            && self.jac_alpha.0 == self.alpha_a
            && (self.static_mode || self.jac_alpha.1 == self.alpha_v)
    }

    fn refresh_jacobian(&mut self, z: &[T; D]) -> Result<()> {
        let mut r = [T::ZERO; D];
        self.residual(z, &mut r);
        self.assemble_jacobian(z)
    }

    /// Advance by one nominal step (`settings.step_s`, or less after a
    /// rejection, growing back by at most a factor 2 per step).
    pub fn step(&mut self) -> Result<()> {
        self.step_max(self.settings.step_s)
    }

    /// Advance by one step of at most `h_max` seconds.
    pub fn step_max(&mut self, h_max: T) -> Result<()> {
        if !h_max.is_finite() || h_max <= T::ZERO {
            return Err(Error::NonFinite { what: "step size" });
        }
        self.static_mode = false;
        let nd = self.ndof();
        let mut h = self.h_next.min(h_max);
        for _attempt in 0..64 {
            self.set_bdf(h);
            // Predictor: Taylor extrapolation of q; previous multipliers.
            let mut z = [T::ZERO; D];
            let half = T::from_f64(0.5);
            for i in 0..nd {
                z[i] = self.q[i] + h * self.v[i] + half * h * h * self.acc[i];
            }
            z[nd] = self.lam[0];
            z[nd + 1] = self.lam[1];
            // A prescribed track holds joint A exactly where it must be.
            if let Some((x, y)) = self.track_position(self.time + h) {
                z[crate::chain::X] = x;
                z[crate::chain::Y] = y;
            }
            let mut fresh = false;
            if !self.jacobian_current() {
                if self.refresh_jacobian(&z).is_err() {
                    return Err(self.diverged("singular Newton matrix"));
                }
                fresh = true;
            }
            match self.newton(&mut z, false) {
                Newton::Converged { iterations, rate } => {
                    self.accept(&z, h);
                    if iterations > 3 || rate > 0.25 {
                        self.jac.invalidate();
                    }
                    if !self.state_is_finite() {
                        return Err(self.diverged("state became non-finite"));
                    }
                    self.h_next = (h * T::from_f64(2.0)).min(self.settings.step_s);
                    return Ok(());
                }
                Newton::Failed => {
                    self.jac.invalidate();
                    if fresh {
                        self.stats.rejected += 1;
                        h *= T::from_f64(0.25);
                        if h < self.settings.min_step_s {
                            return Err(self.diverged("Newton failed at the smallest step"));
                        }
                    }
                }
            }
        }
        Err(self.diverged("too many rejected attempts"))
    }

    fn diverged(&self, reason: &'static str) -> Error {
        Error::Diverged {
            time_s: self.time.to_f64(),
            reason,
        }
    }

    fn accept(&mut self, z: &[T; D], h: T) {
        let nd = self.ndof();
        self.q_old = self.q;
        self.v_old = self.v;
        for i in 0..nd {
            self.q[i] = z[i];
            self.v[i] = self.alpha_v * z[i] + self.bv[i];
            self.acc[i] = self.alpha_a * z[i] + self.ba[i];
        }
        self.lam = [z[nd], z[nd + 1]];
        self.h_old = h;
        self.history = true;
        self.time += h;
        self.stats.steps += 1;
        self.kinematics_positions();
    }

    /// Find the static equilibrium nearest the current shape (gravity,
    /// joint stiffness, floor; no friction or damping), and leave the chain
    /// there at rest. Returns the number of proximal iterations.
    pub fn solve_static(&mut self) -> Result<usize> {
        self.relax()?;
        self.polish_static()
    }

    /// Dynamic relaxation: the real dynamics (gravity, contacts, joint
    /// damping) with kinetic damping — all velocities are zeroed whenever
    /// the kinetic energy passes a peak — until the belt barely moves. Brings
    /// any start (a circle dropped on the floor, a still-oscillating belt)
    /// close to the equilibrium for the Newton polish.
    fn relax(&mut self) -> Result<()> {
        let t0 = self.time;
        let h = self.settings.relax_step_s;
        self.reset_motion();
        let mut ke_prev = T::ZERO;
        let quiet = T::from_f64(1e-3);
        let mut resets = 0usize;
        for _ in 0..self.settings.relax_steps {
            self.step_max(h)?;
            let ke = self.kinetic_energy_j();
            if ke < ke_prev {
                self.reset_motion();
                resets += 1;
                ke_prev = T::ZERO;
                if resets > 3 && self.max_joint_speed_m_s() < quiet {
                    break;
                }
            } else {
                ke_prev = ke;
            }
            if resets > 3 && ke < T::from_f64(1e-9) {
                break;
            }
        }
        self.reset_motion();
        self.time = t0;
        Ok(())
    }

    /// The static residual (without the proximal term) is at the noise
    /// level: every generalised force below 1e-7 of the belt's weight (times
    /// a link length for moments). Soft modes — the material circulating
    /// round the loop while the shape stays put — carry no force and need no
    /// convergence of the position.
    fn in_equilibrium(&mut self, z: &[T; D]) -> bool {
        let nd = self.ndof();
        let (aa, ba) = (self.alpha_a, self.ba);
        self.alpha_a = T::ZERO;
        self.ba = [T::ZERO; D];
        let mut r = [T::ZERO; D];
        self.residual(z, &mut r);
        self.alpha_a = aa;
        self.ba = ba;
        let weight = (self.m * T::from_usize(self.n) + self.roller_kg).to_f64()
            * self.model.gravity_m_s2.to_f64().max(1.0);
        let tol_f = (1e-7 * weight).max(T::epsilon().to_f64() * 1e3 * weight);
        let tol_m = tol_f * self.l.to_f64();
        let close = 1e-9 + T::epsilon().to_f64() * 10.0;
        (0..nd).all(|i| {
            let tol = if self.is_length_coord(i) {
                tol_f
            } else {
                tol_m
            };
            r[i].to_f64().abs() <= tol
        }) && r[nd].to_f64().abs() <= close
            && r[nd + 1].to_f64().abs() <= close
    }

    /// Newton polish of the equilibrium (proximal-point iteration).
    pub(crate) fn polish_static(&mut self) -> Result<usize> {
        let nd = self.ndof();
        self.static_mode = true;
        self.jac.invalidate();
        let mut anchor = [T::ZERO; D];
        anchor[..nd].copy_from_slice(&self.q[..nd]);
        let mut z = [T::ZERO; D];
        z[..nd].copy_from_slice(&self.q[..nd]);
        z[nd] = self.lam[0];
        z[nd + 1] = self.lam[1];
        let tau_max = self.settings.static_tau_max_s;
        let mut tau = T::from_f64(0.2).min(tau_max);
        let result = (|| {
            for it in 0..self.settings.static_iterations {
                let k = T::ONE / (tau * tau);
                self.alpha_v = T::ZERO;
                self.alpha_a = k;
                for i in 0..nd {
                    self.bv[i] = T::ZERO;
                    self.ba[i] = -k * anchor[i];
                }
                let mut trial = z;
                if self.refresh_jacobian(&trial).is_err() {
                    tau *= T::from_f64(0.25);
                    if tau < T::from_f64(1e-4) {
                        return Err(Error::Singular);
                    }
                    continue;
                }
                match self.newton(&mut trial, true) {
                    Newton::Converged { .. } => {
                        let mut dz = [T::ZERO; D];
                        for i in 0..nd {
                            dz[i] = trial[i] - anchor[i];
                        }
                        let moved = self.correction_norm(&dz);
                        z = trial;
                        anchor[..nd].copy_from_slice(&z[..nd]);
                        if (moved <= 10.0 && tau >= tau_max) || self.in_equilibrium(&z) {
                            return Ok(it + 1);
                        }
                        tau = (tau * T::from_f64(2.0)).min(tau_max);
                    }
                    Newton::Failed => {
                        tau *= T::from_f64(0.25);
                        if tau < T::from_f64(1e-4) {
                            return Err(Error::NotConverged {
                                what: "static equilibrium",
                                iterations: it + 1,
                            });
                        }
                    }
                }
            }
            Err(Error::NotConverged {
                what: "static equilibrium",
                iterations: self.settings.static_iterations,
            })
        })();
        self.static_mode = false;
        self.q[..nd].copy_from_slice(&z[..nd]);
        self.lam = [z[nd], z[nd + 1]];
        self.reset_motion();
        if !self.state_is_finite() {
            return Err(Error::Diverged {
                time_s: self.time.to_f64(),
                reason: "static solve produced a non-finite state",
            });
        }
        result
    }
}
#[cfg(test)]
mod jac_check {
    extern crate std;
    use crate::chain::Chain;
    use crate::*;
    fn check(c: &mut Chain<f64, 132>, z: [f64; 132], label: &str) {
        let ns = c.nsys();
        let mut r0 = [0.0; 132];
        c.residual(&z, &mut r0);
        c.build_jacobian(&z);
        let mut worst = 0.0f64;
        let mut worst_at = (0, 0, 0.0, 0.0);
        for j in 0..ns {
            let mut zp = z;
            let h = 1e-7;
            zp[j] += h;
            let mut r1 = [0.0; 132];
            c.residual(&zp, &mut r1);
            let mut zm = z;
            zm[j] -= h;
            let mut r2 = [0.0; 132];
            c.residual(&zm, &mut r2);
            let mut colmax = 0.0f64;
            for i in 0..ns {
                colmax = colmax.max(c.jac.a[i][j].abs());
            }
            for i in 0..ns {
                let fd = (r1[i] - r2[i]) / (2.0 * h);
                let d = (fd - c.jac.a[i][j]).abs() / (colmax + 1e-12);
                if d > worst && !(c.static_mode && (i == 0 || j == 0)) {
                    worst = d;
                    worst_at = (i, j, fd, c.jac.a[i][j]);
                }
            }
        }
        std::eprintln!("{label}: worst rel err {worst:e} at {worst_at:?}");
    }
    #[test]
    fn jacobian_matches_finite_differences() {
        let model = params::Model::paper(params::Variant::E38, params::Method::I).unwrap();
        let mut c = std::boxed::Box::new(ReferenceChain::new(model, Settings::default()).unwrap());
        let nd = c.ndof();
        let mut z = [0.0; 132];
        z[..nd].copy_from_slice(&c.q[..nd]);
        c.static_mode = true;
        c.alpha_v = 0.0;
        c.alpha_a = 1.0 / 0.05f64.powi(2);
        for i in 0..nd {
            c.bv[i] = 0.0;
            c.ba[i] = -c.alpha_a * c.q[i];
        }
        let mut zz = z;
        for i in 2..nd {
            zz[i] += 0.01 * ((i * 7) as f64).sin();
        }
        zz[1] -= 0.003;
        zz[nd] = 3.0;
        zz[nd + 1] = -2.0;
        check(&mut c, zz, "static perturbed");
        c.static_mode = false;
        c.alpha_v = 1000.0;
        c.alpha_a = 1e6;
        for i in 0..nd {
            c.bv[i] = -c.alpha_v * zz[i] + 0.1 * ((i * 3) as f64).cos();
            c.ba[i] = -c.alpha_a * zz[i] + 1.0 * ((i * 5) as f64).cos();
        }
        check(&mut c, zz, "dynamic perturbed");
        c.alpha_v = 0.0;
        c.alpha_a = 0.0;
        for i in 0..nd {
            c.ba[i] = 0.0;
            c.bv[i] = 0.0;
        }
        c.static_mode = true;
        check(&mut c, zz, "pure static");
    }
}

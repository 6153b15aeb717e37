//! The static and dynamic bench tests: the ring settles on a flat floor
//! under its own weight, then a rigid roller is released on its top.

use crate::chain::{Chain, V2};
use crate::law::Material;
use crate::Error;

/// Gravity, m/s².
pub const G: f64 = 9.81;

/// Floor contact: Hunt–Crossley normal force `k·δ^1.5·(1 + 1.5·α·δ̇)` and
/// tanh-regularised Coulomb friction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Stiffness, N/m^1.5.
    pub k: f64,
    /// Hunt–Crossley damping, s/m.
    pub alpha: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// Regularising slip speed, m/s.
    pub v_reg: f64,
}

impl Contact {
    /// A stiff rubber-on-floor contact.
    pub fn floor() -> Self {
        Contact {
            k: 2.0e6,
            alpha: 0.3,
            mu: 0.7,
            v_reg: 0.02,
        }
    }

    /// Normal force for penetration `d` (> 0) growing at `d_dot`, N.
    pub fn normal(&self, d: f64, d_dot: f64) -> f64 {
        (self.k * d * d.sqrt() * (1.0 + 1.5 * self.alpha * d_dot)).max(0.0)
    }

    /// Friction force against slip speed `s`, for normal force `fn_`, N.
    pub fn friction(&self, fn_: f64, s: f64) -> f64 {
        -self.mu * fn_ * (s / self.v_reg).tanh()
    }

    /// Contact stiffness at a load of `load_n`, N/m.
    pub fn stiffness_at(&self, load_n: f64) -> f64 {
        let d = (load_n / self.k).powf(2.0 / 3.0);
        1.5 * self.k * d.sqrt()
    }
}

/// A drop-test configuration.
#[derive(Debug, Clone)]
pub struct DropConfig {
    /// Belt length, m.
    pub length_m: f64,
    /// Belt thickness, m.
    pub thickness_m: f64,
    /// Belt mass, kg.
    pub mass_kg: f64,
    /// Nodes.
    pub nodes: usize,
    /// Axial stiffness EA of the belt, N.
    pub ea_n: f64,
    /// Bending behaviour.
    pub material: Material,
    /// Per-node factor of the elastic law, indexed from the top point A.
    pub ei_scale: Vec<f64>,
    /// Floor contact.
    pub floor: Contact,
}

/// A settled ring.
#[derive(Debug, Clone)]
pub struct Settled {
    /// The chain at rest.
    pub chain: Chain,
    /// Index of the top point A.
    pub a_index: usize,
    /// Height of A's outer surface above the floor, m (A, not the highest
    /// point: the top run may sag a little between two humps).
    pub hs_m: f64,
    /// Overall width, m.
    pub ws_m: f64,
    /// Step used, s.
    pub step_s: f64,
}

impl DropConfig {
    fn step(&self, chain: &Chain, roller_kg: f64) -> f64 {
        let b = self.material.elastic.max_tangent()
            * self.ei_scale.iter().fold(1.0, |a, &b| f64::max(a, b));
        let mut c = self.material.damping.max_slope();
        if let crate::law::FrictionLaw::Tanh { m_c, rate } = self.material.friction {
            c += m_c / rate;
        }
        // The largest load a floor node carries: the weight of a few
        // nodes' share of belt and roller (the bottom run spreads it).
        let load = (self.mass_kg + 2.0 * roller_kg) * G * 4.0 / self.nodes as f64;
        let k = self.floor.stiffness_at(load);
        let cc = self.floor.mu * load / self.floor.v_reg;
        chain.stable_step(b, c, k, cc, 0.6)
    }

    /// Contact forces of the floor (and of the bottom run on the top run,
    /// a plane one thickness up for the nodes of the upper half).
    fn floor_forces(&self, chain: &mut Chain, a_index: usize) {
        let n = chain.n;
        let ht = chain.half_t;
        for i in 0..n {
            let y = chain.x[i][1];
            let mut d = ht - y;
            let ring = (i + n - a_index) % n;
            let upper = ring.min(n - ring) < n / 4;
            if upper {
                d = d.max(3.0 * ht - y);
            }
            if d > 0.0 {
                let fnm = self.floor.normal(d, -chain.v[i][1]);
                let ft = self.floor.friction(fnm, chain.v[i][0]);
                chain.f[i][1] += fnm;
                chain.f[i][0] += ft;
            }
        }
    }

    /// The ring, formed into a circle of its length and put on the floor
    /// with the material turned by `turn` nodes, settles under its own
    /// weight (a settling drag speeds this up; it is off in every test
    /// that follows).
    pub fn settle(&self, turn: usize) -> Result<Settled, Error> {
        let n = self.nodes;
        if n < 8 || !n.is_multiple_of(2) || self.ei_scale.len() != n {
            return Err(Error::Invalid(format!(
                "node count {n} (even, ≥ 8, one factor each)"
            )));
        }
        let r = self.length_m / std::f64::consts::TAU;
        let ht = 0.5 * self.thickness_m;
        // Exact polygon of the rest length.
        let rc = self.length_m / n as f64 / (2.0 * (std::f64::consts::PI / n as f64).sin());
        let x: Vec<V2> = (0..n)
            .map(|i| {
                let phi =
                    -std::f64::consts::FRAC_PI_2 + std::f64::consts::TAU * i as f64 / n as f64;
                [rc * phi.cos(), ht + r + rc * phi.sin() + 1e-4]
            })
            .collect();
        let a_index = n / 2;
        let scale: Vec<f64> = (0..n)
            .map(|i| self.ei_scale[(i + turn + n - a_index) % n])
            .collect();
        let mut chain = Chain::new(
            x,
            self.length_m / n as f64,
            ht,
            self.mass_kg,
            self.ea_n,
            scale,
        );
        let h = self.step(&chain, 0.0);
        // A belt long at rest has no remembered amplitude: settle without
        // the Payne memory, then start it at the settled shape.
        let mat = Material {
            payne: None,
            ..self.material
        };
        let max_steps = (6.0 / h) as usize;
        let min_steps = (1.0 / h) as usize;
        let check = ((0.02 / h) as usize).max(1);
        let mut steps = 0;
        loop {
            chain.internal_forces(&mat, 1.0, 1.0);
            chain.gravity(G);
            self.floor_forces(&mut chain, a_index);
            chain.settling_drag(10.0);
            chain.advance(h);
            chain.update_states(&mat, h);
            steps += 1;
            if steps % check == 0 {
                if !chain.is_finite() {
                    return Err(Error::Unstable {
                        what: "settling ring",
                        t_s: steps as f64 * h,
                    });
                }
                if steps >= min_steps && chain.max_speed() < 2e-4 {
                    break;
                }
            }
            if steps >= max_steps {
                return Err(Error::Unstable {
                    what: "ring did not settle",
                    t_s: steps as f64 * h,
                });
            }
        }
        for v in chain.v.iter_mut() {
            *v = [0.0; 2];
        }
        chain.internal_forces(&mat, 1.0, 1.0);
        chain.reset_memory();
        if std::env::var_os("TRUTH_DEBUG").is_some() {
            let top = chain
                .x
                .iter()
                .map(|p| p[1])
                .fold(f64::NEG_INFINITY, f64::max)
                + ht;
            eprintln!(
                "settled: A {:.1} mm, highest node {:.1} mm",
                (chain.x[a_index][1] + ht) * 1e3,
                top * 1e3
            );
        }
        let hs_m = chain.x[a_index][1] + ht;
        let ws_m = chain.width();
        Ok(Settled {
            chain,
            a_index,
            hs_m,
            ws_m,
            step_s: h,
        })
    }

    /// Release a roller (mass, radius) on A of a settled ring and follow
    /// it for `duration_s`. A's outer-surface height and horizontal
    /// position are recorded every `record_s`.
    pub fn drop(
        &self,
        settled: &Settled,
        roller_kg: f64,
        roller_radius_m: f64,
        duration_s: f64,
        record_s: f64,
    ) -> Result<DropRun, Error> {
        let mut chain = settled.chain.clone();
        let a = settled.a_index;
        let ht = chain.half_t;
        let h = self.step(&chain, roller_kg);
        let mat = self.material;
        let rr = roller_radius_m;
        let mut rx = [chain.x[a][0], chain.x[a][1] + ht + rr];
        let mut rv = [0.0f64; 2];
        let mut rw = 0.0f64;
        let rj = 0.5 * roller_kg * rr * rr;
        let contact = Contact {
            k: 1.0e6,
            alpha: 0.3,
            mu: 0.6,
            v_reg: 0.02,
        };
        let steps = (duration_s / h).ceil() as usize;
        let every = ((record_s / h).round() as usize).max(1);
        let mut run = DropRun::default();
        let n = chain.n;
        for s in 0..=steps {
            if s % every == 0 {
                run.t_s.push(s as f64 * h);
                run.a_height_m.push(chain.x[a][1] + ht);
                run.a_x_m.push(chain.x[a][0]);
                if !chain.is_finite() || !rx[1].is_finite() {
                    return Err(Error::Unstable {
                        what: "drop test",
                        t_s: s as f64 * h,
                    });
                }
            }
            if s == steps {
                break;
            }
            chain.internal_forces(&mat, 1.0, 1.0);
            chain.gravity(G);
            self.floor_forces(&mut chain, a);
            let mut rf = [0.0, -roller_kg * G];
            let mut rt = 0.0;
            // Roller on the floor (it may not pass through it).
            if rx[1] < rr {
                rf[1] += self.floor.normal(rr - rx[1], -rv[1]);
            }
            // Roller on the belt's segments (outer surface).
            for j in 0..n {
                let k = (j + 1) % n;
                let p = chain.x[j];
                let q = chain.x[k];
                let d = [q[0] - p[0], q[1] - p[1]];
                let l2 = d[0] * d[0] + d[1] * d[1];
                let w = [rx[0] - p[0], rx[1] - p[1]];
                let u = ((w[0] * d[0] + w[1] * d[1]) / l2).clamp(0.0, 1.0);
                let c = [p[0] + u * d[0] - rx[0], p[1] + u * d[1] - rx[1]];
                let dist = (c[0] * c[0] + c[1] * c[1]).sqrt();
                let pen = rr + ht - dist;
                if pen <= 0.0 || dist < 1e-9 {
                    continue;
                }
                // Unit normal from the roller's centre to the belt.
                let nn = [c[0] / dist, c[1] / dist];
                let vb = [
                    (1.0 - u) * chain.v[j][0] + u * chain.v[k][0],
                    (1.0 - u) * chain.v[j][1] + u * chain.v[k][1],
                ];
                let rel = [vb[0] - rv[0], vb[1] - rv[1]];
                let pen_dot = -(rel[0] * nn[0] + rel[1] * nn[1]);
                let fnm = contact.normal(pen, pen_dot);
                // Slip of the belt against the roller's surface.
                let tt = [-nn[1], nn[0]];
                let surf = rw * rr; // roller surface speed along tt at the contact
                let slip = rel[0] * tt[0] + rel[1] * tt[1] - surf;
                let ft = contact.friction(fnm, slip);
                let fb = [fnm * nn[0] + ft * tt[0], fnm * nn[1] + ft * tt[1]];
                chain.f[j][0] += (1.0 - u) * fb[0];
                chain.f[j][1] += (1.0 - u) * fb[1];
                chain.f[k][0] += u * fb[0];
                chain.f[k][1] += u * fb[1];
                rf[0] -= fb[0];
                rf[1] -= fb[1];
                rt -= rr * ft;
            }
            chain.advance(h);
            chain.update_states(&mat, h);
            rv[0] += h * rf[0] / roller_kg;
            rv[1] += h * rf[1] / roller_kg;
            rx[0] += h * rv[0];
            rx[1] += h * rv[1];
            rw += h * rt / rj;
        }
        let tail = (0.5 / record_s).max(1.0) as usize;
        let m = run.a_height_m.len();
        let from = m.saturating_sub(tail);
        run.hd_m = run.a_height_m[from..].iter().sum::<f64>() / (m - from).max(1) as f64;
        run.wd_m = chain.width();
        run.step_s = h;
        Ok(run)
    }
}

/// What a drop test recorded.
#[derive(Debug, Clone, Default)]
pub struct DropRun {
    /// Times since the release, s.
    pub t_s: Vec<f64>,
    /// Height of A's outer surface, m.
    pub a_height_m: Vec<f64>,
    /// Horizontal position of A, m.
    pub a_x_m: Vec<f64>,
    /// Final height of A (mean of the last half second), m.
    pub hd_m: f64,
    /// Final width, m.
    pub wd_m: f64,
    /// Step used, s.
    pub step_s: f64,
}

impl DropRun {
    /// Period (s) and log decrement from the first two maxima of A's height
    /// about the final height, if there are two clear maxima.
    pub fn period_and_decrement(&self) -> Option<(f64, f64)> {
        let h = &self.a_height_m;
        let t = &self.t_s;
        let hd = self.hd_m;
        // Skip the first fall: start after the first minimum below hd.
        let mut i = 1;
        while i + 1 < h.len() && !(h[i] < hd && h[i] <= h[i - 1] && h[i] <= h[i + 1]) {
            i += 1;
        }
        let mut maxima = Vec::new();
        while i + 1 < h.len() && maxima.len() < 2 {
            if h[i] > hd && h[i] >= h[i - 1] && h[i] > h[i + 1] {
                // A maximum of a half-wave above hd: the largest until A crosses hd down.
                let mut j = i;
                let mut best = i;
                while j + 1 < h.len() && h[j] > hd {
                    if h[j] > h[best] {
                        best = j;
                    }
                    j += 1;
                }
                maxima.push(best);
                // Wait for the next crossing up.
                while j + 1 < h.len() && h[j] <= hd {
                    j += 1;
                }
                i = j;
            } else {
                i += 1;
            }
        }
        if maxima.len() < 2 {
            return None;
        }
        let a1 = h[maxima[0]] - hd;
        let a2 = h[maxima[1]] - hd;
        if a2 < 2e-4 || a1 <= a2 {
            return None;
        }
        Some((t[maxima[1]] - t[maxima[0]], (a1 / a2).ln()))
    }
}

//! Contact laws: the floor under the belt's outer surface, self-contact
//! between the inner surfaces of non-adjacent links, and the two wheels of
//! the bending-resistance rig under the belt's inner surface.
//!
//! Both are penalty contacts (a stiff spring-damper along the normal, no
//! adhesion); the floor adds Coulomb friction regularised below a small slip
//! speed. A contact reports its force and its tangent stiffness and damping
//! so that the implicit integrator can put it in its Jacobian.

use crate::kinematics::{Kinematics, LinkPoint};
use crate::params::{Floor, SelfContact};
use crate::real::Real;

/// One active contact.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Contact<T> {
    /// Where the force acts.
    pub a: LinkPoint<T>,
    /// Reaction point (self-contact), receiving `-force`.
    pub b: Option<LinkPoint<T>>,
    /// Force on `a`, N.
    pub force: (T, T),
    /// Unit normal (direction of the normal force on `a`).
    pub normal: (T, T),
    /// Normal stiffness, N/m.
    pub kn: T,
    /// Normal damping, N·s/m.
    pub cn: T,
    /// Unit tangent.
    pub tangent: (T, T),
    /// Tangential damping (friction slope), N·s/m.
    pub ct: T,
    /// What the belt touches.
    pub kind: ContactKind,
}

/// What a contact is made with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ContactKind {
    /// The floor (bench tests).
    Floor,
    /// Another link of the belt.
    SelfContact,
    /// The rig's drive wheel (its speed is prescribed; friction drives the belt).
    Drive,
    /// The rig's idler (frictionless; its axle is a degree of freedom).
    Idler,
    /// A road wheel or support roller of a running gear (frictionless,
    /// fixed centre).
    Fixed,
    /// The ground under a running gear (frictionless; its height is a
    /// degree of freedom pushed up by the robot's weight).
    Ground,
}

/// Most fixed-centre wheels (road wheels, support rollers) besides the drive
/// and the idler.
pub(crate) const MAX_FIXED_WHEELS: usize = crate::gear::MAX_WHEELS - 2;

/// A road wheel or support roller: a frictionless wheel whose centre is
/// fixed in the robot's frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FixedWheel<T> {
    /// Centre, m.
    pub x: T,
    /// Centre, m.
    pub y: T,
    /// Radius, m.
    pub r: T,
}

/// The flat ground under a running gear: a horizontal surface at height
/// `y` (a degree of freedom) under the belt's outer surface.
#[derive(Debug, Clone, Copy)]
pub(crate) struct GroundContact<T> {
    /// Height of the ground, m, and its speed, m/s.
    pub y: T,
    /// Its vertical speed, m/s.
    pub vy: T,
}

/// The rig's wheels as the contact laws see them: the drive wheel is
/// centred at the origin, the idler at `idler_x·(idler_ux, idler_uy)`
/// (`(idler_x, 0)` on the paper's rig), the fixed wheels where they are.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Wheels<T> {
    /// Drive wheel radius, m.
    pub drive_r: T,
    /// Idler radius, m.
    pub idler_r: T,
    /// Idler axle position and speed (m, m/s): a degree of freedom.
    pub idler_x: T,
    /// Idler axle speed, m/s.
    pub idler_vx: T,
    /// Drive speed, clockwise positive, rad/s.
    pub drive_omega: T,
    /// Normal stiffness, N/m.
    pub stiffness: T,
    /// Normal damping, N·s/m.
    pub damping: T,
    /// Coulomb friction coefficient at the drive wheel.
    pub friction: T,
    /// Slip speed below which friction is regularised (linear), m/s.
    pub slip_speed: T,
    /// Unit direction the idler's axle slides along (from the drive's
    /// centre through the idler's): `(1, 0)` on the paper's rig.
    pub idler_ux: T,
    /// Its y component.
    pub idler_uy: T,
    /// Road wheels and support rollers (the first `fixed_count`).
    pub fixed: [FixedWheel<T>; MAX_FIXED_WHEELS],
    /// How many of `fixed` are there.
    pub fixed_count: usize,
}

/// What the belt can touch: the floor, itself, the rig's wheels.
pub(crate) struct Contacts<T> {
    /// The floor (bench tests).
    pub floor: Floor<T>,
    /// Self-contact between the inner surfaces of non-adjacent links.
    pub self_contact: SelfContact<T>,
    /// The floor is there (off on the rig).
    pub floor_enabled: bool,
    /// The rig's wheels, when the chain runs on the rig.
    pub wheels: Option<Wheels<T>>,
    /// The ground under a running gear (frictionless, movable).
    pub ground: Option<GroundContact<T>>,
}

/// Links per box in the self-contact broad phase.
const CHUNK: usize = 4;

/// Penetration over which a penalty contact's stiffness ramps up from zero,
/// m. A C¹ onset keeps Newton from chattering when a point sits right at the
/// surface (the force is `k·p²/(2δ)` below `δ`, `k·(p − δ/2)` above).
pub(crate) const ONSET_M: f64 = 5.0e-5;

/// Smoothed penalty: `(force, stiffness)` for penetration `p > 0`.
#[inline]
pub(crate) fn penalty<T: Real>(k: T, p: T) -> (T, T) {
    let d = T::from_f64(ONSET_M);
    if p < d {
        (k * p * p / (d + d), k * p / d)
    } else {
        (k * (p - d * T::from_f64(0.5)), k)
    }
}

/// Energy stored in a smoothed penalty spring of stiffness `k` that pushes
/// with `force` at tangent stiffness `kn` ([`penalty`]'s outputs), J.
pub(crate) fn penalty_energy<T: Real>(k: T, force: T, kn: T) -> T {
    let d = T::from_f64(ONSET_M);
    let half = T::from_f64(0.5);
    let sixth = T::from_f64(1.0 / 6.0);
    if k <= T::ZERO {
        return T::ZERO;
    }
    if kn < k {
        // Below the onset: p = kn·d/k, energy k·p³/(6d).
        let p = kn * d / k;
        k * p * p * p * sixth / d
    } else {
        let p = force / k + half * d;
        k * d * d * sixth + k * (half * (p * p - d * d) - half * d * (p - d))
    }
}

impl<T: Real> Contacts<T> {
    /// Energy stored in the contact springs at the kinematics `kin`
    /// (positions only), J.
    pub(crate) fn spring_energy_j<const D: usize>(&self, kin: &Kinematics<T, D>) -> T {
        let mut e = T::ZERO;
        self.for_each_contact(kin, false, |_, ct| {
            let k = match ct.kind {
                ContactKind::Floor => self.floor.stiffness_n_per_m,
                ContactKind::SelfContact => self.self_contact.stiffness_n_per_m,
                // The running gear's wheels and its ground use the wheel
                // contact's stiffness.
                ContactKind::Drive
                | ContactKind::Idler
                | ContactKind::Fixed
                | ContactKind::Ground => self.wheels.map_or(T::ZERO, |w| w.stiffness),
            };
            let f = ct.force.0 * ct.normal.0 + ct.force.1 * ct.normal.1;
            e += penalty_energy(k, f, ct.kn);
        });
        e
    }

    /// The floor and self-contact of a model, no wheels.
    pub(crate) fn new(floor: Floor<T>, self_contact: SelfContact<T>) -> Self {
        Contacts {
            floor,
            self_contact,
            floor_enabled: true,
            wheels: None,
            ground: None,
        }
    }

    /// Visit every active contact. `with_velocity = false` in static solves.
    pub(crate) fn for_each_contact<const D: usize, F: FnMut(&Kinematics<T, D>, &Contact<T>)>(
        &self,
        kin: &Kinematics<T, D>,
        with_velocity: bool,
        mut f: F,
    ) {
        if self.floor_enabled {
            self.floor_contacts(kin, with_velocity, &mut f);
        }
        if self.self_contact.enabled {
            self.self_contacts(kin, with_velocity, &mut f);
        }
        if let Some(w) = self.wheels {
            self.wheel_contacts(kin, &w, with_velocity, &mut f);
            if let Some(g) = self.ground {
                self.ground_contacts(kin, &w, &g, with_velocity, &mut f);
            }
        }
    }

    /// The belt's outer surface (both corners of every link) on the ground
    /// of a running gear: frictionless, the wheels' contact law.
    fn ground_contacts<const D: usize, F: FnMut(&Kinematics<T, D>, &Contact<T>)>(
        &self,
        kin: &Kinematics<T, D>,
        w: &Wheels<T>,
        g: &GroundContact<T>,
        with_velocity: bool,
        f: &mut F,
    ) {
        let up = (T::ZERO, T::ONE);
        let right = (T::ONE, T::ZERO);
        for k in 0..kin.n {
            for u in [T::ZERO, kin.l] {
                let p = LinkPoint {
                    link: k,
                    u,
                    w: kin.half_t,
                };
                let pos = kin.point_position(p);
                if pos.1 >= g.y {
                    continue;
                }
                let (fk, kn) = penalty(w.stiffness, g.y - pos.1);
                let (mut fnorm, mut cn) = (fk, T::ZERO);
                if with_velocity {
                    let (_, vy) = kin.point_velocity(p);
                    fnorm -= w.damping * (vy - g.vy);
                    cn = w.damping;
                }
                if fnorm <= T::ZERO {
                    continue;
                }
                f(
                    kin,
                    &Contact {
                        a: p,
                        b: None,
                        force: (T::ZERO, fnorm),
                        normal: up,
                        kn,
                        cn,
                        tangent: right,
                        ct: T::ZERO,
                        kind: ContactKind::Ground,
                    },
                );
            }
        }
    }

    /// Inner surface of every link against the drive wheel and the idler:
    /// the point of the link's inner edge closest to the wheel's centre.
    fn wheel_contacts<const D: usize, F: FnMut(&Kinematics<T, D>, &Contact<T>)>(
        &self,
        kin: &Kinematics<T, D>,
        w: &Wheels<T>,
        with_velocity: bool,
        f: &mut F,
    ) {
        let reach = kin.l + kin.half_t * T::from_f64(4.0);
        let fixed = w.fixed.iter().take(w.fixed_count.min(MAX_FIXED_WHEELS));
        let wheels = [
            (ContactKind::Drive, T::ZERO, T::ZERO, w.drive_r),
            (
                ContactKind::Idler,
                w.idler_x * w.idler_ux,
                w.idler_x * w.idler_uy,
                w.idler_r,
            ),
        ]
        .into_iter()
        .chain(fixed.map(|fw| (ContactKind::Fixed, fw.x, fw.y, fw.r)));
        for (kind, cx, cy, r) in wheels {
            for k in 0..kin.n {
                // Broad phase: the link's start joint must be near the rim.
                let (dx0, dy0) = (kin.px[k] - cx, kin.py[k] - cy);
                let lim = r + reach;
                if dx0.abs() > lim || dy0.abs() > lim {
                    continue;
                }
                let (c, s) = (kin.c[k], kin.s[k]);
                // Start of the inner edge: joint − (t/2)·e'.
                let ox = kin.px[k] + kin.half_t * s;
                let oy = kin.py[k] - kin.half_t * c;
                // The wheel must be on the inner side of the link.
                if (cx - ox) * (-s) + (cy - oy) * c >= T::ZERO {
                    continue;
                }
                let along = ((cx - ox) * c + (cy - oy) * s).clamp(T::ZERO, kin.l);
                let px = ox + along * c;
                let py = oy + along * s;
                let (rx, ry) = (px - cx, py - cy);
                let d2 = rx * rx + ry * ry;
                if d2 >= r * r || d2 <= T::ZERO {
                    continue;
                }
                let d = d2.sqrt();
                let nrm = (rx / d, ry / d);
                let tangent = (-nrm.1, nrm.0);
                let p = LinkPoint {
                    link: k,
                    u: along,
                    w: -kin.half_t,
                };
                let (fk, kn) = penalty(w.stiffness, r - d);
                let (mut fnorm, mut cn) = (fk, T::ZERO);
                let mut vel = (T::ZERO, T::ZERO);
                if with_velocity {
                    vel = kin.point_velocity(p);
                    let (ox, oy) = if kind == ContactKind::Idler {
                        (w.idler_vx * w.idler_ux, w.idler_vx * w.idler_uy)
                    } else {
                        (T::ZERO, T::ZERO)
                    };
                    let vn = (vel.0 - ox) * nrm.0 + (vel.1 - oy) * nrm.1;
                    fnorm -= w.damping * vn;
                    cn = w.damping;
                }
                if fnorm <= T::ZERO {
                    continue;
                }
                let (mut ft, mut ct) = (T::ZERO, T::ZERO);
                if with_velocity && kind == ContactKind::Drive && w.friction > T::ZERO {
                    // Wheel surface velocity for a clockwise speed ω: (ω·r_y, −ω·r_x).
                    let sx = w.drive_omega * ry;
                    let sy = -w.drive_omega * rx;
                    let slip = (vel.0 - sx) * tangent.0 + (vel.1 - sy) * tangent.1;
                    let cap = w.friction * fnorm;
                    if slip.abs() < w.slip_speed {
                        ct = cap / w.slip_speed;
                        ft = -ct * slip;
                    } else {
                        ft = if slip > T::ZERO { -cap } else { cap };
                    }
                }
                f(
                    kin,
                    &Contact {
                        a: p,
                        b: None,
                        force: (
                            fnorm * nrm.0 + ft * tangent.0,
                            fnorm * nrm.1 + ft * tangent.1,
                        ),
                        normal: nrm,
                        kn,
                        cn,
                        tangent,
                        ct,
                        kind,
                    },
                );
            }
        }
    }

    fn floor_contacts<const D: usize, F: FnMut(&Kinematics<T, D>, &Contact<T>)>(
        &self,
        kin: &Kinematics<T, D>,
        with_velocity: bool,
        f: &mut F,
    ) {
        let fl = self.floor;
        let up = (T::ZERO, T::ONE);
        let right = (T::ONE, T::ZERO);
        for k in 0..kin.n {
            for u in [T::ZERO, kin.l] {
                let p = LinkPoint {
                    link: k,
                    u,
                    w: kin.half_t,
                };
                let pos = kin.point_position(p);
                if pos.1 >= T::ZERO {
                    continue;
                }
                let pen = -pos.1;
                let (vx, vy) = if with_velocity {
                    kin.point_velocity(p)
                } else {
                    (T::ZERO, T::ZERO)
                };
                let (fk, kn) = penalty(fl.stiffness_n_per_m, pen);
                let fnorm = fk - fl.damping_n_s_per_m * vy;
                if fnorm <= T::ZERO {
                    continue;
                }
                let mut ft = T::ZERO;
                let mut ct = T::ZERO;
                if with_velocity && fl.friction > T::ZERO {
                    let cap = fl.friction * fnorm;
                    if vx.abs() < fl.slip_speed_m_s {
                        ct = cap / fl.slip_speed_m_s;
                        ft = -ct * vx;
                    } else {
                        ft = if vx > T::ZERO { -cap } else { cap };
                    }
                }
                f(
                    kin,
                    &Contact {
                        a: p,
                        b: None,
                        force: (ft, fnorm),
                        normal: up,
                        kn,
                        cn: if with_velocity {
                            fl.damping_n_s_per_m
                        } else {
                            T::ZERO
                        },
                        tangent: right,
                        ct,
                        kind: ContactKind::Floor,
                    },
                );
            }
        }
    }

    /// Axis-aligned box of links `[first, first + CHUNK)`, inflated by the
    /// thickness.
    fn chunk_box<const D: usize>(kin: &Kinematics<T, D>, first: usize) -> [T; 4] {
        let mut b = [kin.px[first], kin.px[first], kin.py[first], kin.py[first]];
        let last = (first + CHUNK).min(kin.n);
        for k in first..=last {
            // px/py hold n + 1 joint positions (the last closes the loop).
            let (x, y) = (kin.px[k], kin.py[k]);
            b[0] = b[0].min(x);
            b[1] = b[1].max(x);
            b[2] = b[2].min(y);
            b[3] = b[3].max(y);
        }
        let t = kin.half_t * T::from_f64(2.0);
        [b[0] - t, b[1] + t, b[2] - t, b[3] + t]
    }

    fn self_contacts<const D: usize, F: FnMut(&Kinematics<T, D>, &Contact<T>)>(
        &self,
        kin: &Kinematics<T, D>,
        with_velocity: bool,
        f: &mut F,
    ) {
        let n = kin.n;
        let chunks = n.div_ceil(CHUNK);
        if chunks < 3 {
            return;
        }
        let mut boxes = [[T::ZERO; 4]; D];
        for (ci, b) in boxes.iter_mut().enumerate().take(chunks) {
            *b = Self::chunk_box(kin, ci * CHUNK);
        }
        for ca in 0..chunks {
            for cb in 0..chunks {
                let gap = ca.abs_diff(cb);
                if gap <= 1 || gap == chunks - 1 {
                    continue;
                }
                let (ba, bb) = (boxes[ca], boxes[cb]);
                if ba[1] < bb[0] || bb[1] < ba[0] || ba[3] < bb[2] || bb[3] < ba[2] {
                    continue;
                }
                for a in (ca * CHUNK)..((ca + 1) * CHUNK).min(n) {
                    for b in (cb * CHUNK)..((cb + 1) * CHUNK).min(n) {
                        self.point_vs_link(kin, a, b, with_velocity, f);
                    }
                }
            }
        }
    }

    /// The inner corner at the end of link `a` against the inner surface of
    /// link `b`.
    fn point_vs_link<const D: usize, F: FnMut(&Kinematics<T, D>, &Contact<T>)>(
        &self,
        kin: &Kinematics<T, D>,
        a: usize,
        b: usize,
        with_velocity: bool,
        f: &mut F,
    ) {
        let n = kin.n;
        let dist = {
            let d = a.abs_diff(b);
            d.min(n - d)
        };
        if dist <= 2 {
            return;
        }
        // Inner surfaces must face each other.
        let facing = kin.c[a] * kin.c[b] + kin.s[a] * kin.s[b];
        if facing >= T::ZERO {
            return;
        }
        let t = kin.half_t * T::from_f64(2.0);
        let pa = LinkPoint {
            link: a,
            u: kin.l,
            w: -kin.half_t,
        };
        let p = kin.point_position(pa);
        let (cb, sb) = (kin.c[b], kin.s[b]);
        // Inner edge of b starts at px[b] - (t/2) e'_b; interior normal -e'_b.
        let ox = kin.px[b] + kin.half_t * sb;
        let oy = kin.py[b] - kin.half_t * cb;
        let rx = p.0 - ox;
        let ry = p.1 - oy;
        let along = rx * cb + ry * sb;
        if along < T::ZERO || along > kin.l {
            return;
        }
        let nrm = (sb, -cb);
        let d = rx * nrm.0 + ry * nrm.1;
        if d >= T::ZERO || d <= -t {
            return;
        }
        let pb = LinkPoint {
            link: b,
            u: along,
            w: -kin.half_t,
        };
        let sc = self.self_contact;
        let (mut fnorm, kn) = penalty(sc.stiffness_n_per_m, -d);
        let mut cn = T::ZERO;
        if with_velocity {
            let va = kin.point_velocity(pa);
            let vb = kin.point_velocity(pb);
            let dd = (va.0 - vb.0) * nrm.0 + (va.1 - vb.1) * nrm.1;
            fnorm -= sc.damping_n_s_per_m * dd;
            cn = sc.damping_n_s_per_m;
        }
        if fnorm <= T::ZERO {
            return;
        }
        f(
            kin,
            &Contact {
                a: pa,
                b: Some(pb),
                force: (fnorm * nrm.0, fnorm * nrm.1),
                normal: nrm,
                kn,
                cn,
                tangent: (cb, sb),
                ct: T::ZERO,
                kind: ContactKind::SelfContact,
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn penalty_energy_is_the_integral_of_the_force() {
        let k = 1.0e5;
        for p in [1e-6, 2e-5, 5e-5, 8e-5, 1e-3, 4e-3] {
            let n = 20_000;
            let h = p / n as f64;
            let w: f64 = (0..n).map(|i| penalty(k, (i as f64 + 0.5) * h).0 * h).sum();
            let (f, kn) = penalty(k, p);
            let e = penalty_energy(k, f, kn);
            assert!((e - w).abs() <= 1e-6 * w.max(1e-12), "{p}: {e} vs {w}");
        }
    }
}

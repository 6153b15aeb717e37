//! Kinematics of a closed chain of rigid links: the pin chain's coordinate
//! layout, joint angles, link points and the positions and velocities of
//! the joints, shared by the pin chain ([`crate::chain`]), the bushing chain
//! ([`crate::bushing`]), the contact laws ([`crate::contact`]) and the
//! estimator's builder.
//!
//! Link `k` runs from joint `k` to joint `k+1` at the absolute angle `θ_k`;
//! `e_k = (cos θ_k, sin θ_k)` is its axis and `e'_k = (−sin θ_k, cos θ_k)`
//! its outward normal. The joint angle at joint `j` is `ζ_j = θ_j − θ_{j−1}`
//! and, at the closing joint, `ζ₀ = θ₀ − θ_{N−1} − 2π`.

use crate::real::Real;

/// Index of joint A's x in the pin chain's coordinates.
pub(crate) const X: usize = 0;
/// Index of joint A's y.
pub(crate) const Y: usize = 1;
/// Index of the first link angle `θ₀` (link `k` at `TH + k`).
pub(crate) const TH: usize = 2;

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

/// The regular polygon of `n` links of length `l` (a circle formed from the
/// belt): its circumradius (m) and the angle of link `k` when joint 0 is at
/// the top and the links run clockwise, rad.
pub(crate) struct Polygon<T> {
    /// Circumradius, m.
    pub radius_m: T,
    n: T,
    pi: T,
    two_pi: T,
}

impl<T: Real> Polygon<T> {
    /// The polygon of `n` links of length `l` (`two_pi` = 2π in the
    /// chain's number type).
    pub(crate) fn new(n: usize, l: T, two_pi: T) -> Self {
        let nn = T::from_usize(n);
        let pi = T::from_f64(core::f64::consts::PI);
        let (sin_half, _) = (pi / nn).sin_cos();
        Polygon {
            radius_m: l / (T::from_f64(2.0) * sin_half),
            n: nn,
            pi,
            two_pi,
        }
    }

    /// Absolute angle of link `k`, rad.
    pub(crate) fn link_angle(&self, k: usize) -> T {
        let (pi, nn) = (self.pi, self.n);
        let half = T::from_f64(0.5);
        let phi = pi * half - self.two_pi * T::from_usize(k) / nn;
        phi - pi * half - pi / nn
    }
}

/// A material point of a link: `u` along the link axis from its start joint,
/// `w` along its outward normal (positive: outer surface).
#[derive(Debug, Clone, Copy)]
pub(crate) struct LinkPoint<T> {
    pub link: usize,
    pub u: T,
    pub w: T,
}

/// Positions and velocities of the joints of the last evaluated state.
pub(crate) struct Kinematics<T, const D: usize> {
    pub n: usize,
    pub l: T,
    pub half_t: T,
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
    /// Kinematics of an `n`-link belt (links of length `l`, half thickness
    /// `half_t`) at the origin, at rest.
    pub(crate) fn new(n: usize, l: T, half_t: T) -> Self {
        let z = [T::ZERO; D];
        Kinematics {
            n,
            l,
            half_t,
            c: z,
            s: z,
            px: z,
            py: z,
            pvx: z,
            pvy: z,
            rate: z,
        }
    }

    /// Position of a material point (after the kinematics are filled in).
    #[inline]
    pub(crate) fn point_position(&self, p: LinkPoint<T>) -> (T, T) {
        let k = p.link;
        let (c, s) = (self.c[k], self.s[k]);
        (
            self.px[k] + p.u * c - p.w * s,
            self.py[k] + p.u * s + p.w * c,
        )
    }

    /// Velocity of a material point (after the kinematics are filled in).
    #[inline]
    pub(crate) fn point_velocity(&self, p: LinkPoint<T>) -> (T, T) {
        let k = p.link;
        let (c, s) = (self.c[k], self.s[k]);
        let w = self.rate[k];
        (
            self.pvx[k] + w * (-p.u * s - p.w * c),
            self.pvy[k] + w * (p.u * c - p.w * s),
        )
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

    /// Add `sign·J_Pᵀ·d` of a link point to `g`, with `J_P` the point's
    /// Jacobian with respect to the pin chain's coordinates
    /// `(x₀, y₀, θ₀ … θ_{N−1})`. Returns the range of indices touched.
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
}

//! Dense LU factorisation with equilibration and partial pivoting, fixed
//! capacity `D`, no heap: the one linear solver of the crate, public so
//! host code can solve its small systems with it too.
//!
//! The implicit integrator solves one (N+4)×(N+4) system per Newton
//! iteration. The matrix is factored once and reused across iterations and
//! steps while Newton keeps converging fast (simplified Newton).
//!
//! Before factoring, the matrix is **equilibrated** by powers of two:
//! columns whose largest entry exceeds one are scaled down to it, then rows
//! whose largest entry is below one are scaled up. The Newton matrix mixes
//! units — masses over h² (~1e6) against link lengths (~0.06) in the
//! closure rows and a zero block for the multipliers — so unscaled, the
//! multipliers' pivots come out near 1e-5 (1e-9 at small steps): harmless
//! in floating point, but below the resolution of 32.32 fixed point, where
//! they made the factorisation "singular" and the multipliers garbage.
//! Scaling columns only *down* and rows only *up* keeps the right-hand side
//! and the unknowns at least as large as they were, so fixed point loses no
//! resolution in them (scaling the rows of 1e6 down instead would drop 20
//! bits of the residual). Powers of two scale exactly in binary floating
//! point, so `f64` results move only by a different rounding order.
//!
//! The elimination skips zero multipliers, so a **banded** matrix costs
//! O(n·b²) to factor. [`Band`] is the banded mode of the same solver: it
//! reorders the unknowns symmetrically (so a loop of coupled blocks becomes
//! a band), factors with [`Dense::factor`], records the extent of every
//! column of the factors and solves with [`Dense::solve_banded`], whose
//! triangular sweeps skip the zeros outside them.
//!
//! ```
//! use trackbelt::linalg::Dense;
//! // 2x + y = 5, x + 3y = 10.
//! let mut m = Dense::<f64, 2>::from_matrix([[2.0, 1.0], [1.0, 3.0]]);
//! m.factor()?;
//! let mut b = [5.0, 10.0];
//! m.solve(&mut b);
//! assert!((b[0] - 1.0).abs() < 1e-12 && (b[1] - 3.0).abs() < 1e-12);
//! # Ok::<(), trackbelt::Error>(())
//! ```

use crate::error::{Error, Result};
use crate::real::Real;

/// A square matrix of dimension `n ≤ D`, factored in place.
pub struct Dense<T, const D: usize> {
    /// The entries, row by row; only the leading `n × n` block is used.
    /// After [`factor`](Self::factor) it holds the LU factors of the
    /// equilibrated, row-permuted matrix, **transposed**: `a[k][i]` is
    /// `L[i][k]` below the diagonal (`i > k`) and `a[j][i]` is `U[i][j]`
    /// on and above it (`i ≤ j`), so both triangular sweeps of
    /// [`solve`](Self::solve) read contiguous memory.
    pub a: [[T; D]; D],
    n: usize,
    piv: [u16; D],
    /// Row scale factors (powers of two, ≥ 1) applied before factoring.
    row: [T; D],
    /// Column scale factors (powers of two, ≤ 1) applied before factoring.
    col: [T; D],
    factored: bool,
}

/// Largest and smallest exponent of a scale factor: keeps `2^e` and the
/// scaled entries representable in 32.32 fixed point.
const MAX_EXP: i32 = 30;

/// `2^-e` with `2^(e-1) ≤ m < 2^e` (so `m·2^-e ∈ [0.5, 1)`), clamped to
/// `2^±MAX_EXP`; 1 for zero or non-finite `m`.
fn inverse_pow2(m: f64) -> f64 {
    if m.is_nan() || m <= 0.0 || m.is_infinite() {
        return 1.0;
    }
    let (_, e) = libm::frexp(m);
    libm::ldexp(1.0, (-e).clamp(-MAX_EXP, MAX_EXP))
}

impl<T: Real, const D: usize> Default for Dense<T, D> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Real, const D: usize> Dense<T, D> {
    /// A zero matrix of dimension 0 (call [`reset`](Self::reset)).
    pub fn new() -> Self {
        Dense {
            a: [[T::ZERO; D]; D],
            n: 0,
            piv: [0; D],
            row: [T::ONE; D],
            col: [T::ONE; D],
            factored: false,
        }
    }

    /// Zero the leading `n × n` block and set the dimension.
    pub fn reset(&mut self, n: usize) {
        self.n = n.min(D);
        for row in self.a.iter_mut().take(self.n) {
            for x in row.iter_mut().take(self.n) {
                *x = T::ZERO;
            }
        }
        self.factored = false;
    }

    /// The full `D × D` matrix `a`, not yet factored.
    pub fn from_matrix(a: [[T; D]; D]) -> Self {
        let mut m = Self::new();
        m.a = a;
        m.n = D;
        m
    }

    /// The dimension `n` of the system.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// [`factor`](Self::factor) succeeded and nothing changed since.
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Mark the factors stale (the entries are about to change).
    pub fn invalidate(&mut self) {
        self.factored = false;
    }

    /// Scale columns down, then rows up, by powers of two (see the module
    /// docs): `A ← R·A·C`, remembered for [`solve`](Self::solve).
    /// A non-finite (or saturated) entry is an error: scaling must not
    /// turn it into an ordinary number.
    fn equilibrate(&mut self) -> Result<()> {
        let n = self.n;
        let mut cs = [1.0f64; D];
        for (j, c) in cs.iter_mut().enumerate().take(n) {
            let mut m = 0.0f64;
            for row in self.a.iter().take(n) {
                if !row[j].is_finite() {
                    return Err(Error::Singular);
                }
                m = m.max(row[j].to_f64().abs());
            }
            *c = inverse_pow2(m).min(1.0);
        }
        let mut rs = [1.0f64; D];
        for (r, row) in rs.iter_mut().zip(self.a.iter()).take(n) {
            let mut m = 0.0f64;
            for (x, c) in row.iter().zip(cs.iter()).take(n) {
                m = m.max(x.to_f64().abs() * c);
            }
            *r = inverse_pow2(m).max(1.0);
        }
        // One rounding per entry: r·c lies in [2^-30, 2^30], representable
        // in every build.
        for (i, row) in self.a.iter_mut().enumerate().take(n) {
            self.row[i] = T::from_f64(rs[i]);
            for (x, &c) in row.iter_mut().zip(cs.iter()).take(n) {
                let f = rs[i] * c;
                if f != 1.0 && *x != T::ZERO {
                    *x *= T::from_f64(f);
                }
            }
        }
        for (c, &f) in self.col.iter_mut().zip(cs.iter()).take(n) {
            *c = T::from_f64(f);
        }
        Ok(())
    }

    /// LU with partial pivoting, after equilibration. Rows are swapped
    /// physically; the factors are then transposed in place (see
    /// [`a`](Self::a)). A zero or non-finite pivot is [`Error::Singular`].
    pub fn factor(&mut self) -> Result<()> {
        self.factored = false;
        self.equilibrate()?;
        let n = self.n;
        for k in 0..n {
            let mut p = k;
            let mut best = self.a[k][k].abs();
            for i in (k + 1)..n {
                let v = self.a[i][k].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if best <= T::ZERO || !best.is_finite() {
                self.factored = false;
                return Err(Error::Singular);
            }
            self.piv[k] = p as u16;
            if p != k {
                self.a.swap(p, k);
            }
            let (top, bottom) = self.a.split_at_mut(k + 1);
            let rk = &top[k];
            let inv = T::ONE / rk[k];
            for ri in bottom.iter_mut().take(n - k - 1) {
                let f = ri[k] * inv;
                ri[k] = f;
                if f != T::ZERO {
                    for (x, &y) in ri[k + 1..n].iter_mut().zip(&rk[k + 1..n]) {
                        *x -= f * y;
                    }
                }
            }
        }
        for i in 0..n {
            for j in 0..i {
                let x = self.a[i][j];
                self.a[i][j] = self.a[j][i];
                self.a[j][i] = x;
            }
        }
        self.factored = true;
        Ok(())
    }

    /// Apply the row scaling `R` to a right-hand side.
    fn scale_rhs(&self, b: &mut [T]) {
        for (x, &r) in b.iter_mut().zip(self.row.iter()).take(self.n) {
            *x *= r;
        }
    }

    /// Apply the column scaling `C` to the solution of the scaled system.
    fn unscale_solution(&self, b: &mut [T]) {
        for (x, &c) in b.iter_mut().zip(self.col.iter()).take(self.n) {
            *x *= c;
        }
    }

    /// Solve `A x = b` in place (after [`factor`](Self::factor)): solves
    /// `(R·A·C) y = R·b`, then `x = C·y`. Only the first `n` entries of `b`
    /// are used.
    pub fn solve(&self, b: &mut [T]) {
        self.solve_within(b, |_| self.n, |_| 0);
    }

    /// [`solve`](Self::solve) with the factors' column extents of `band`
    /// (recorded by [`Band::factor`]): the triangular sweeps skip the zeros
    /// outside them, with the same result. `b` is in the band's order.
    pub fn solve_banded(&self, b: &mut [T], band: &Band<D>) {
        self.solve_within(b, |k| band.l_end[k], |j| band.u_start[j]);
    }

    /// The solve, column by column (the factors are stored transposed, so
    /// every column is a contiguous row of `a`, and the updates of one
    /// column are independent of each other): column `k` of L is read up
    /// to row `l_end(k)` (exclusive), column `j` of U from row
    /// `u_start(j)`; the rest must be zero. The forward sweep gives every
    /// entry of `b` its updates in the order a row-by-row sweep would; the
    /// back sweep in the opposite order (results differ by rounding).
    #[inline]
    fn solve_within<L: Fn(usize) -> usize, U: Fn(usize) -> usize>(
        &self,
        b: &mut [T],
        l_end: L,
        u_start: U,
    ) {
        let n = self.n.min(b.len());
        self.scale_rhs(b);
        for k in 0..n {
            let p = self.piv[k] as usize;
            if p != k && p < n {
                b.swap(p, k);
            }
        }
        for (k, col) in self.a.iter().enumerate().take(n) {
            let bk = b[k];
            let end = l_end(k).clamp(k + 1, n);
            if bk != T::ZERO && end > k + 1 {
                for (x, &l) in b[k + 1..end].iter_mut().zip(&col[k + 1..end]) {
                    *x -= l * bk;
                }
            }
        }
        for j in (0..n).rev() {
            let col = &self.a[j];
            let bj = b[j] / col[j];
            b[j] = bj;
            let start = u_start(j).min(j);
            if bj != T::ZERO {
                for (x, &u) in b[start..j].iter_mut().zip(&col[start..j]) {
                    *x -= u * bj;
                }
            }
        }
        self.unscale_solution(b);
    }
}

/// The banded mode of [`Dense`]: a symmetric reordering of the unknowns
/// that makes the matrix banded, and the extent of every column of its
/// factors, so the triangular sweeps skip the zeros outside the band.
///
/// ```
/// use trackbelt::linalg::{Band, Dense};
/// // A cyclic tridiagonal 4×4 system, unknowns reordered 0, 3, 1, 2
/// // (position of unknown i: perm[i]).
/// let a = [[4.0, 1.0, 0.0, 1.0], [1.0, 4.0, 1.0, 0.0], [0.0, 1.0, 4.0, 1.0], [1.0, 0.0, 1.0, 4.0]];
/// let mut m = Dense::<f64, 4>::from_matrix(a);
/// let mut band = Band::new([0, 2, 3, 1]);
/// band.factor(&mut m)?;
/// let x = [1.0, -2.0, 3.0, 0.5];
/// let mut b = [0.0; 4];
/// for i in 0..4 {
///     b[i] = (0..4).map(|j| a[i][j] * x[j]).sum();
/// }
/// band.solve(&m, &mut b);
/// for i in 0..4 {
///     assert!((b[i] - x[i]).abs() < 1e-12);
/// }
/// # Ok::<(), trackbelt::Error>(())
/// ```
pub struct Band<const D: usize> {
    /// Position of every unknown in the reordered system.
    perm: [usize; D],
    /// One past the last nonzero row of every column of L.
    l_end: [usize; D],
    /// First nonzero row of every column of U.
    u_start: [usize; D],
}

impl<const D: usize> Band<D> {
    /// A band for the reordering `perm` (unknown `i` goes to position
    /// `perm[i]`; the first `n` entries must be a permutation of `0..n`
    /// for a system of dimension `n`, checked by [`factor`](Self::factor)).
    pub fn new(perm: [usize; D]) -> Self {
        Band {
            perm,
            l_end: [0; D],
            u_start: [0; D],
        }
    }

    /// Reorder the rows and columns of `m` (a matrix in the original
    /// order), factor it and record the extents of the factors' columns.
    pub fn factor<T: Real>(&mut self, m: &mut Dense<T, D>) -> Result<()> {
        let ns = m.n;
        let mut seen = [false; D];
        for &p in self.perm.iter().take(ns) {
            if p >= ns || seen[p] {
                return Err(Error::InvalidParameter {
                    field: "band.perm",
                    reason: "not a permutation of the unknowns",
                });
            }
            seen[p] = true;
        }
        self.permute(m);
        m.factor()?;
        // The factors are stored transposed: row `k` of `m.a` is column
        // `k` of L (after the diagonal) and of U (up to it).
        for (k, col) in m.a.iter().enumerate().take(ns) {
            self.l_end[k] = col[k + 1..ns]
                .iter()
                .rposition(|&x| x != T::ZERO)
                .map_or(k + 1, |p| k + 2 + p);
            self.u_start[k] = col[..k].iter().position(|&x| x != T::ZERO).unwrap_or(k);
        }
        Ok(())
    }

    /// Reorder rows and columns of `m` (`perm`, checked by the caller).
    fn permute<T: Real>(&self, m: &mut Dense<T, D>) {
        let ns = m.n;
        // Columns, row by row.
        let mut tmp = [T::ZERO; D];
        for row in m.a.iter_mut().take(ns) {
            for c in 0..ns {
                tmp[self.perm[c]] = row[c];
            }
            row[..ns].copy_from_slice(&tmp[..ns]);
        }
        // Rows, following the cycles of the permutation.
        let mut done = [false; D];
        for start in 0..ns {
            if done[start] {
                continue;
            }
            let mut carried = m.a[start];
            let mut at = start;
            // A cycle is at most ns long.
            for _ in 0..ns {
                let to = self.perm[at];
                core::mem::swap(&mut carried, &mut m.a[to]);
                done[to] = true;
                at = to;
                if at == start {
                    break;
                }
            }
        }
    }

    /// Solve with `m` as [`factor`](Self::factor) left it: `b` (in the
    /// original order) is the right-hand side on entry, the solution on
    /// exit.
    pub fn solve<T: Real>(&self, m: &Dense<T, D>, b: &mut [T; D]) {
        let ns = m.n;
        let mut p = [T::ZERO; D];
        for i in 0..ns {
            p[self.perm[i]] = b[i];
        }
        m.solve_banded(&mut p[..ns], self);
        for i in 0..ns {
            b[i] = p[self.perm[i]];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_pivoting_system() {
        let mut m: Dense<f64, 4> = Dense::new();
        m.reset(3);
        let a = [[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [3.0, 0.0, 1.0]];
        for i in 0..3 {
            m.a[i][..3].copy_from_slice(&a[i]);
        }
        m.factor().unwrap();
        let x = [1.0, -2.0, 0.5];
        let mut b = [0.0; 3];
        for i in 0..3 {
            b[i] = (0..3).map(|j| a[i][j] * x[j]).sum();
        }
        m.solve(&mut b);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-12);
        }
    }

    /// The shape of the integrator's Newton matrix — a stiff mass block
    /// (1e6) bordered by closure constraints (entries ~0.06, zero diagonal
    /// block) — solved in 32.32 fixed point: the multipliers must come out
    /// right, not as garbage from pivots below the resolution.
    #[test]
    #[cfg(feature = "fixed")]
    fn fixed_point_solves_a_badly_scaled_saddle_point_system() {
        use crate::real::Fx;
        const N: usize = 8;
        let mut a = [[0.0f64; N]; N];
        for i in 0..6 {
            a[i][i] = 1.0e6 * (1.0 + 0.1 * i as f64);
            if i + 1 < 6 {
                a[i][i + 1] = 2.0e5;
                a[i + 1][i] = 2.0e5;
            }
            let (g0, g1) = (0.06 * (0.3 * i as f64).sin(), 0.06 * (0.3 * i as f64).cos());
            a[i][6] = g0;
            a[6][i] = g0;
            a[i][7] = g1;
            a[7][i] = g1;
        }
        let x = [1e-4, -2e-4, 3e-4, 5e-5, -1e-4, 2e-4, 1.5, -0.7];
        let mut b = [0.0; N];
        for i in 0..N {
            b[i] = (0..N).map(|j| a[i][j] * x[j]).sum();
        }
        let mut m: Dense<Fx, N> = Dense::new();
        m.reset(N);
        for i in 0..N {
            for j in 0..N {
                m.a[i][j] = Fx::from_f64(a[i][j]);
            }
        }
        m.factor().unwrap();
        let mut bx = [Fx::ZERO; N];
        for i in 0..N {
            bx[i] = Fx::from_f64(b[i]);
        }
        m.solve(&mut bx);
        for i in 0..6 {
            assert!((bx[i].to_f64() - x[i]).abs() < 1e-8, "x[{i}] = {:?}", bx[i]);
        }
        // The closure rows' right-hand side (~1e-5) is resolved to 2.3e-10,
        // which alone moves the multipliers by about 1 %. Unscaled, they
        // come out as -13 and 0.96.
        for i in 6..N {
            assert!((bx[i].to_f64() - x[i]).abs() < 0.05, "λ[{i}] = {:?}", bx[i]);
        }
    }

    #[test]
    #[cfg(feature = "fixed")]
    fn saturated_or_nan_entries_are_an_error_not_scaled_away() {
        use crate::real::Fx;
        let mut m: Dense<Fx, 2> = Dense::new();
        m.reset(2);
        m.a[0][0] = Fx::from_f64(1e10); // saturates
        m.a[1][1] = Fx::ONE;
        assert_eq!(m.factor(), Err(Error::Singular));
        let mut m: Dense<f64, 2> = Dense::new();
        m.reset(2);
        m.a[0][0] = f64::NAN;
        m.a[1][1] = 1.0;
        assert_eq!(m.factor(), Err(Error::Singular));
    }

    #[test]
    fn singular_is_an_error() {
        let mut m: Dense<f64, 2> = Dense::new();
        m.reset(2);
        m.a[0][0] = 1.0;
        m.a[0][1] = 2.0;
        m.a[1][0] = 2.0;
        m.a[1][1] = 4.0;
        assert_eq!(m.factor(), Err(Error::Singular));
    }
}

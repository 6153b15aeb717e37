//! Dense LU factorisation with partial pivoting, fixed capacity `D`.
//!
//! The implicit integrator solves one (N+4)×(N+4) system per Newton
//! iteration. The matrix is factored once and reused across iterations and
//! steps while Newton keeps converging fast (simplified Newton).

use crate::error::{Error, Result};
use crate::real::Real;

/// A square matrix of dimension `n ≤ D`, factored in place.
pub(crate) struct Dense<T, const D: usize> {
    pub a: [[T; D]; D],
    pub n: usize,
    piv: [u16; D],
    factored: bool,
}

impl<T: Real, const D: usize> Dense<T, D> {
    pub fn new() -> Self {
        Dense {
            a: [[T::ZERO; D]; D],
            n: 0,
            piv: [0; D],
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

    pub fn is_factored(&self) -> bool {
        self.factored
    }

    pub fn invalidate(&mut self) {
        self.factored = false;
    }

    /// LU with partial pivoting. Rows are swapped physically.
    pub fn factor(&mut self) -> Result<()> {
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
        self.factored = true;
        Ok(())
    }

    /// Row swapped with row `k` at step `k` of the factorisation.
    pub fn pivot(&self, k: usize) -> usize {
        self.piv.get(k).map_or(k, |&p| p as usize)
    }

    /// Solve `A x = b` in place (after [`factor`](Self::factor)).
    pub fn solve(&self, b: &mut [T]) {
        let n = self.n.min(b.len());
        for k in 0..n {
            let p = self.piv[k] as usize;
            if p != k && p < n {
                b.swap(p, k);
            }
        }
        for i in 0..n {
            let row = &self.a[i];
            let mut s = b[i];
            for (x, &y) in row[..i].iter().zip(&b[..i]) {
                s -= *x * y;
            }
            b[i] = s;
        }
        for i in (0..n).rev() {
            let row = &self.a[i];
            let mut s = b[i];
            for (x, &y) in row[i + 1..n].iter().zip(&b[i + 1..n]) {
                s -= *x * y;
            }
            b[i] = s / row[i];
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

//! A small Levenberg–Marquardt least-squares fitter for a handful of
//! parameters whose residual is expensive (one simulation per evaluation).
//!
//! The Jacobian is taken by forward differences (one evaluation per
//! parameter), parameters may have box bounds (a step is projected onto
//! them), and the evaluation budget is bounded.
//!
//! ```
//! use trackbelt_host::fit::{levenberg_marquardt, Options};
//! // Fit y = a·exp(b·x) to exact data.
//! let xs: Vec<f64> = (0..20).map(|i| i as f64 * 0.1).collect();
//! let ys: Vec<f64> = xs.iter().map(|x| 2.0 * (0.7 * x).exp()).collect();
//! let r = levenberg_marquardt(
//!     |p: &[f64]| Ok::<_, String>(xs.iter().zip(&ys).map(|(x, y)| y - p[0] * (p[1] * x).exp()).collect()),
//!     &[1.0, 0.0],
//!     &[(0.0, 10.0), (-5.0, 5.0)],
//!     &Options::default(),
//! ).unwrap();
//! assert!((r.params[0] - 2.0).abs() < 1e-4 && (r.params[1] - 0.7).abs() < 1e-4);
//! ```

/// Settings of the fit.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    /// Most outer iterations (each costs one Jacobian).
    pub max_iterations: usize,
    /// Stop when an accepted step lowers the sum of squares by less than
    /// this fraction.
    pub rel_tol: f64,
    /// Finite-difference step per parameter (absolute, in parameter units).
    pub fd_step: f64,
    /// Most residual evaluations in total.
    pub max_evaluations: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            max_iterations: 12,
            rel_tol: 1e-4,
            fd_step: 1e-3,
            max_evaluations: 80,
        }
    }
}

/// Result of a fit.
#[derive(Debug, Clone)]
pub struct FitResult {
    /// Best parameters found.
    pub params: Vec<f64>,
    /// Residual at the best parameters.
    pub residual: Vec<f64>,
    /// Sum of squared residuals there.
    pub sum_sq: f64,
    /// Residual evaluations spent.
    pub evaluations: usize,
}

fn sum_sq(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

/// Minimise the sum of squares of `residual(p)` from `start` within
/// `bounds` (one `(lo, hi)` per parameter).
pub fn levenberg_marquardt<E, F>(
    mut residual: F,
    start: &[f64],
    bounds: &[(f64, f64)],
    opt: &Options,
) -> Result<FitResult, E>
where
    F: FnMut(&[f64]) -> Result<Vec<f64>, E>,
{
    let np = start.len();
    let clamp = |p: &mut [f64]| {
        for (x, &(lo, hi)) in p.iter_mut().zip(bounds) {
            *x = x.clamp(lo, hi);
        }
    };
    let mut p = start.to_vec();
    clamp(&mut p);
    let mut r = residual(&p)?;
    let mut evals = 1;
    let mut s = sum_sq(&r);
    let mut lambda = 1e-2;
    for _ in 0..opt.max_iterations {
        if evals + np + 1 > opt.max_evaluations || np == 0 {
            break;
        }
        // Forward-difference Jacobian, stepping away from the bounds.
        let mut jac = vec![vec![0.0; r.len()]; np];
        for k in 0..np {
            let mut q = p.clone();
            let (lo, hi) = bounds[k];
            let h = if p[k] + opt.fd_step <= hi || p[k] - opt.fd_step < lo {
                opt.fd_step
            } else {
                -opt.fd_step
            };
            q[k] += h;
            let rq = residual(&q)?;
            evals += 1;
            for (j, (a, b)) in rq.iter().zip(&r).enumerate() {
                jac[k][j] = (a - b) / h;
            }
        }
        // Normal equations.
        let mut jtj = vec![vec![0.0; np]; np];
        let mut jtr = vec![0.0; np];
        for a in 0..np {
            for b in 0..np {
                jtj[a][b] = jac[a].iter().zip(&jac[b]).map(|(x, y)| x * y).sum();
            }
            jtr[a] = jac[a].iter().zip(&r).map(|(x, y)| x * y).sum();
        }
        let mut improved = false;
        let mut rel = 0.0;
        for _ in 0..6 {
            let mut m = jtj.clone();
            for a in 0..np {
                m[a][a] += lambda * jtj[a][a].max(1e-12);
            }
            let Some(delta) = solve(m, jtr.iter().map(|x| -x).collect()) else {
                lambda *= 10.0;
                continue;
            };
            let mut q: Vec<f64> = p.iter().zip(&delta).map(|(a, d)| a + d).collect();
            clamp(&mut q);
            if evals + 1 > opt.max_evaluations {
                break;
            }
            let rq = residual(&q)?;
            evals += 1;
            let sq = sum_sq(&rq);
            if sq < s {
                rel = (s - sq) / s.max(1e-300);
                p = q;
                r = rq;
                s = sq;
                lambda = (lambda / 5.0).max(1e-7);
                improved = true;
                break;
            }
            lambda *= 8.0;
        }
        if !improved || rel < opt.rel_tol {
            break;
        }
    }
    Ok(FitResult {
        params: p,
        residual: r,
        sum_sq: s,
        evaluations: evals,
    })
}

/// Solve the small dense system `m·x = b` by Gaussian elimination with
/// partial pivoting; `None` when singular.
pub fn solve(mut m: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    for c in 0..n {
        let piv = (c..n).max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))?;
        if m[piv][c].abs() < 1e-300 || !m[piv][c].is_finite() {
            return None;
        }
        m.swap(c, piv);
        b.swap(c, piv);
        let (top, bottom) = m.split_at_mut(c + 1);
        let pivot_row = &top[c];
        for (k, row) in bottom.iter_mut().enumerate() {
            let f = row[c] / pivot_row[c];
            for (x, p) in row[c..n].iter_mut().zip(&pivot_row[c..n]) {
                *x -= f * p;
            }
            b[c + 1 + k] -= f * b[c];
        }
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|j| m[i][j] * x[j]).sum();
        x[i] = (b[i] - s) / m[i][i];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

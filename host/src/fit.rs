//! The one Levenberg–Marquardt least-squares fitter of the host, shared by
//! the calibration and the diagnosis: a handful of parameters whose
//! residual is expensive (one simulation per evaluation).
//!
//! * The Jacobian is taken by forward differences, its columns evaluated in
//!   parallel (on the current `rayon` pool); a column whose point does not
//!   evaluate, or that a bound leaves no room for, is zero.
//! * Every iteration tries two damping levels side by side (λ and 8λ;
//!   always both, so the result does not depend on the number of threads)
//!   and keeps the better if it lowers the cost.
//! * A refused iteration leaves the point, and so its Jacobian, unchanged:
//!   the next iteration reuses that Jacobian instead of evaluating it
//!   again. The evaluation budget still charges it, so the iterations, the
//!   fit and its result are the same as with a fresh Jacobian; only the
//!   time falls (by about a fifth on a dynamic series' fits, where one
//!   or more of each fit's six or seven iterations is refused).
//! * Parameters have box bounds (a step is clamped onto them) and the
//!   largest component of a step may be limited.
//! * An optional Tikhonov regulariser pulls the first parameters towards a
//!   prior: cost = |r|² + Σ (w·(xᵢ − priorᵢ))².
//! * It stops after `max_iterations`, when the evaluation budget would be
//!   exceeded, when the problem says it is good enough
//!   ([`Problem::quality`] at most `tolerance`), or when an iteration gains
//!   less than `rel_tol` of the cost (less than `stall_gain` once the
//!   quality is at most `stall_quality`).
//!
//! ```
//! use trackbelt_host::fit::{fit, Options, Problem};
//! // Fit y = a·exp(b·x) to exact data.
//! struct Exp(Vec<f64>, Vec<f64>);
//! impl Problem for Exp {
//!     type Output = Vec<f64>;
//!     fn evaluate(&self, p: &[f64]) -> Option<Vec<f64>> {
//!         Some(self.0.iter().zip(&self.1).map(|(x, y)| y - p[0] * (p[1] * x).exp()).collect())
//!     }
//!     fn residuals(&self, r: &Vec<f64>) -> Vec<f64> { r.clone() }
//!     fn clamp(&self, p: &mut [f64]) {
//!         p[0] = p[0].clamp(0.0, 10.0);
//!         p[1] = p[1].clamp(-5.0, 5.0);
//!     }
//! }
//! let xs: Vec<f64> = (0..20).map(|i| i as f64 * 0.1).collect();
//! let ys: Vec<f64> = xs.iter().map(|x| 2.0 * (0.7 * x).exp()).collect();
//! let opts = Options { max_iterations: 50, rel_tol: 1e-12, ..Options::new(vec![1e-6; 2]) };
//! let r = fit(&Exp(xs, ys), &[1.0, 0.0], &opts, &|| {}).unwrap();
//! assert!((r.params[0] - 2.0).abs() < 1e-4 && (r.params[1] - 0.7).abs() < 1e-4);
//! ```

use crate::error::{Error, Result};
use crate::progress::Progress;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A least-squares problem: parameters → an evaluation (e.g. a
/// simulation's figures) → residuals.
pub trait Problem: Sync {
    /// What one evaluation yields (kept for the best point).
    type Output: Send;
    /// Evaluate at `x`; `None` when the point does not evaluate (e.g. the
    /// simulation diverged).
    fn evaluate(&self, x: &[f64]) -> Option<Self::Output>;
    /// Residuals of an evaluation (the same length for every point).
    fn residuals(&self, out: &Self::Output) -> Vec<f64>;
    /// Clamp `x` onto the bounds.
    fn clamp(&self, x: &mut [f64]);
    /// How far from good enough an evaluation is (e.g. the largest relative
    /// error in percent); the fit stops once it is at most
    /// [`Options::tolerance`]. Default: never good enough.
    fn quality(&self, out: &Self::Output) -> f64 {
        let _ = out;
        f64::INFINITY
    }
}

/// Settings of a fit.
#[derive(Debug, Clone)]
pub struct Options {
    /// Forward-difference step per parameter (parameter units).
    pub fd_step: Vec<f64>,
    /// Most iterations (each costs one Jacobian and two trial points).
    pub max_iterations: usize,
    /// Most evaluations in total: no iteration starts that could exceed it.
    /// A reused Jacobian (after a refused iteration) is charged the
    /// evaluations it would have cost, so the budget buys the same
    /// iterations whether or not it is reused.
    pub max_evaluations: usize,
    /// Stop once [`Problem::quality`] is at most this.
    pub tolerance: f64,
    /// Stop when an accepted step lowers the cost by less than this
    /// fraction.
    pub rel_tol: f64,
    /// Once [`Problem::quality`] is at most `stall_quality`, stop already
    /// when a step gains less than `stall_gain`.
    pub stall_quality: f64,
    /// See `stall_quality`.
    pub stall_gain: f64,
    /// Largest |component| of a step (larger steps are scaled down).
    pub max_step: f64,
    /// Regulariser weight per unit of parameter (0: none).
    pub regularisation: f64,
    /// The prior the regulariser pulls towards (its length is the number of
    /// regularised leading parameters).
    pub prior: Vec<f64>,
    /// Initial damping.
    pub lambda: f64,
}

impl Options {
    /// Defaults for the given finite-difference steps: 12 iterations, no
    /// evaluation limit, no tolerance, `rel_tol` 1e-4, no step limit, no
    /// regulariser, λ = 0.01.
    pub fn new(fd_step: Vec<f64>) -> Options {
        Options {
            fd_step,
            max_iterations: 12,
            max_evaluations: usize::MAX,
            tolerance: f64::NEG_INFINITY,
            rel_tol: 1e-4,
            stall_quality: f64::NEG_INFINITY,
            stall_gain: 0.0,
            max_step: f64::INFINITY,
            regularisation: 0.0,
            prior: Vec::new(),
            lambda: 1e-2,
        }
    }
}

/// Outcome of [`fit`].
#[derive(Debug, Clone)]
pub struct Fit<O> {
    /// Best parameters found.
    pub params: Vec<f64>,
    /// The evaluation there.
    pub output: O,
    /// Its residuals.
    pub residuals: Vec<f64>,
    /// The cost there (residuals and regulariser).
    pub cost: f64,
    /// Iterations run.
    pub iterations: usize,
    /// Evaluations spent (a reused Jacobian costs none; see
    /// [`Options::max_evaluations`]).
    pub evaluations: usize,
    /// The last Jacobian, one row per residual (empty when no iteration
    /// ran).
    pub jacobian: Vec<Vec<f64>>,
}

/// The cost of residuals `r` at `x`: |r|² plus the regulariser.
pub fn cost(r: &[f64], x: &[f64], prior: &[f64], reg: f64) -> f64 {
    r.iter().map(|v| v * v).sum::<f64>()
        + prior
            .iter()
            .zip(x)
            .map(|(p, x)| {
                let v = reg * (x - p);
                v * v
            })
            .sum::<f64>()
}

/// One damped Gauss–Newton step: solve
/// `(JᵀJ + RᵀR + λ·diag) δ = −(Jᵀr + Rᵀρ)` (the diagonal floored at 1e-6);
/// `None` when singular.
pub fn lm_step(
    jac: &[Vec<f64>],
    r: &[f64],
    x: &[f64],
    prior: &[f64],
    reg: f64,
    lambda: f64,
) -> Option<Vec<f64>> {
    let n = x.len();
    let mut a = vec![vec![0.0; n]; n];
    let mut g = vec![0.0; n];
    for (row, ri) in jac.iter().zip(r) {
        for i in 0..n {
            g[i] += row[i] * ri;
            for j in 0..n {
                a[i][j] += row[i] * row[j];
            }
        }
    }
    for (i, (p, xi)) in prior.iter().zip(x).enumerate() {
        a[i][i] += reg * reg;
        g[i] += reg * (reg * (xi - p));
    }
    for (i, row) in a.iter_mut().enumerate() {
        row[i] += lambda * row[i].max(1e-6);
    }
    solve(a, g.iter().map(|v| -v).collect())
}

/// Most unknowns of one fit (the capacity of the dense solver used).
pub const MAX_PARAMS: usize = 16;

/// Solve the small dense system `m·x = b` with the core's LU solver
/// ([`trackbelt::linalg::Dense`]: equilibration, partial pivoting); `None`
/// when singular, not finite or larger than [`MAX_PARAMS`].
pub fn solve(a: Vec<Vec<f64>>, b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    if n > MAX_PARAMS || a.len() != n || a.iter().any(|row| row.len() != n) {
        return None;
    }
    let mut m = Box::new(trackbelt::linalg::Dense::<f64, MAX_PARAMS>::new());
    m.reset(n);
    for (dst, src) in m.a.iter_mut().zip(&a) {
        dst[..n].copy_from_slice(src);
    }
    m.factor().ok()?;
    let mut x = b;
    m.solve(&mut x);
    x.iter().all(|v| v.is_finite()).then_some(x)
}

struct Counted<'a, P: Problem + ?Sized> {
    problem: &'a P,
    evaluations: AtomicUsize,
    progress: &'a dyn Progress,
}

impl<P: Problem + ?Sized> Counted<'_, P> {
    fn eval(&self, x: &[f64]) -> Option<P::Output> {
        let f = self.problem.evaluate(x);
        self.evaluations.fetch_add(1, Ordering::SeqCst);
        self.progress.step();
        f
    }

    fn jacobian(&self, x: &[f64], r0: &[f64], fd_step: &[f64]) -> Vec<Vec<f64>> {
        let cols: Vec<Vec<f64>> = (0..x.len())
            .into_par_iter()
            .map(|i| {
                let mut xp = x.to_vec();
                xp[i] += fd_step[i];
                self.problem.clamp(&mut xp);
                let h = xp[i] - x[i];
                match self.eval(&xp) {
                    Some(f) if h != 0.0 => self
                        .problem
                        .residuals(&f)
                        .iter()
                        .zip(r0)
                        .map(|(a, b)| (a - b) / h)
                        .collect(),
                    _ => vec![0.0; r0.len()],
                }
            })
            .collect();
        (0..r0.len())
            .map(|k| cols.iter().map(|c| c[k]).collect())
            .collect()
    }
}

/// Fit `problem` from `start` (clamped onto the bounds first), calling
/// `progress` once per evaluation. An error when the start does not
/// evaluate.
pub fn fit<P: Problem + ?Sized>(
    problem: &P,
    start: &[f64],
    opts: &Options,
    progress: &dyn Progress,
) -> Result<Fit<P::Output>> {
    let np = start.len();
    let lm = Counted {
        problem,
        evaluations: AtomicUsize::new(0),
        progress,
    };
    let (prior, reg) = (&opts.prior[..], opts.regularisation);
    let mut x = start.to_vec();
    problem.clamp(&mut x);
    let mut f = lm.eval(&x).ok_or(Error::StartDiverged)?;
    let mut r = problem.residuals(&f);
    let mut c = cost(&r, &x, prior, reg);
    let mut lambda = opts.lambda;
    let mut iterations = 0;
    let mut jac = Vec::new();
    // Whether `jac` is the Jacobian at the current `x` (no step accepted
    // since it was taken), and the evaluations charged for reusing it.
    let mut jac_current = false;
    let mut reused = 0usize;
    while iterations < opts.max_iterations
        && problem.quality(&f) > opts.tolerance
        && lm.evaluations.load(Ordering::SeqCst) + reused + np + 2 <= opts.max_evaluations
    {
        iterations += 1;
        if jac_current {
            reused += np;
        } else {
            jac = lm.jacobian(&x, &r, &opts.fd_step);
            jac_current = true;
        }
        // Two damping levels tried side by side (always both: the result
        // does not depend on the thread count).
        let candidates: Vec<Vec<f64>> = [lambda, lambda * 8.0]
            .iter()
            .filter_map(|&l| {
                let mut d = lm_step(&jac, &r, &x, prior, reg, l)?;
                let big = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                if big > opts.max_step {
                    d.iter_mut().for_each(|v| *v = *v * opts.max_step / big);
                }
                let mut xn: Vec<f64> = x.iter().zip(&d).map(|(a, b)| a + b).collect();
                problem.clamp(&mut xn);
                Some(xn)
            })
            .collect();
        let evals: Vec<Option<P::Output>> = candidates.par_iter().map(|xn| lm.eval(xn)).collect();
        let mut best: Option<(usize, f64, Vec<f64>)> = None;
        for (k, (xn, fe)) in candidates.iter().zip(&evals).enumerate() {
            if let Some(fe) = fe {
                let rn = problem.residuals(fe);
                let cn = cost(&rn, xn, prior, reg);
                if cn < c && best.as_ref().is_none_or(|(_, b, _)| cn < *b) {
                    best = Some((k, cn, rn));
                }
            }
        }
        match best {
            Some((k, cn, rn)) => {
                if let Some(fe) = evals.into_iter().nth(k).flatten() {
                    f = fe;
                }
                x = candidates.into_iter().nth(k).unwrap_or(x);
                jac_current = false;
                r = rn;
                let gain = (c - cn) / c.max(1e-300);
                c = cn;
                lambda = if k == 0 {
                    (lambda / 4.0).max(1e-6)
                } else {
                    lambda * 2.0
                };
                if gain < opts.rel_tol
                    || (gain < opts.stall_gain && problem.quality(&f) <= opts.stall_quality)
                {
                    break;
                }
            }
            None => {
                lambda *= 30.0;
                if lambda > 1e6 {
                    break;
                }
            }
        }
    }
    Ok(Fit {
        params: x,
        output: f,
        residuals: r,
        cost: c,
        iterations,
        evaluations: lm.evaluations.load(Ordering::SeqCst),
        jacobian: jac,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solver_solves() {
        let n = 7;
        let mut a = vec![vec![0.0; n]; n];
        for (i, row) in a.iter_mut().enumerate() {
            row[i] = 2.0 + i as f64;
            row[(i + 1) % n] = 1.0;
        }
        let x = solve(a.clone(), vec![1.0; n]).unwrap();
        for row in &a {
            let s: f64 = row.iter().zip(&x).map(|(m, x)| m * x).sum();
            assert!((s - 1.0).abs() < 1e-12);
        }
        assert!(solve(vec![vec![0.0; 2]; 2], vec![1.0, 1.0]).is_none());
    }

    /// Rosenbrock's valley, recording every point evaluated.
    struct Valley(std::sync::Mutex<Vec<Vec<f64>>>);
    impl Problem for Valley {
        type Output = Vec<f64>;
        fn evaluate(&self, p: &[f64]) -> Option<Vec<f64>> {
            self.0.lock().ok()?.push(p.to_vec());
            Some(vec![10.0 * (p[1] - p[0] * p[0]), 1.0 - p[0]])
        }
        fn residuals(&self, r: &Vec<f64>) -> Vec<f64> {
            r.clone()
        }
        fn clamp(&self, p: &mut [f64]) {
            p.iter_mut().for_each(|v| *v = v.clamp(-5.0, 5.0));
        }
    }

    #[test]
    fn a_refused_step_reuses_the_jacobian_and_the_budget_still_charges_it() {
        // A tiny first damping on a curved valley: the first steps
        // overshoot and are refused.
        let opts = Options {
            max_iterations: 40,
            rel_tol: 1e-14,
            lambda: 1e-6,
            ..Options::new(vec![1e-7; 2])
        };
        let r = fit(&Valley(Default::default()), &[-1.2, 1.0], &opts, &|| {}).unwrap();
        assert!((r.params[0] - 1.0).abs() < 1e-6 && (r.params[1] - 1.0).abs() < 1e-6);
        // Its first ten iterations, away from the minimum (where both
        // trial steps can land on the same point): steps were refused (a
        // fresh Jacobian every iteration would cost four evaluations
        // each), and no point was evaluated twice.
        let ten = Options {
            max_iterations: 10,
            ..opts.clone()
        };
        let valley = Valley(Default::default());
        let r = fit(&valley, &[-1.2, 1.0], &ten, &|| {}).unwrap();
        let points = valley.0.into_inner().unwrap();
        assert_eq!(points.len(), r.evaluations);
        assert!(
            r.evaluations < 1 + 4 * r.iterations,
            "{} evaluations",
            r.evaluations
        );
        for (i, p) in points.iter().enumerate() {
            assert!(!points[..i].contains(p), "{p:?} evaluated twice");
        }
        // The budget charges a reused Jacobian: the same budget buys the
        // same iterations and the same point as when every iteration
        // evaluated it afresh (1 + 4 per iteration).
        let k = 5;
        let budget = Options {
            max_evaluations: 1 + 4 * k,
            ..opts.clone()
        };
        let capped = fit(&Valley(Default::default()), &[-1.2, 1.0], &budget, &|| {}).unwrap();
        let short = Options {
            max_iterations: k,
            ..opts
        };
        let stopped = fit(&Valley(Default::default()), &[-1.2, 1.0], &short, &|| {}).unwrap();
        assert_eq!(capped.iterations, k);
        assert_eq!(capped.params, stopped.params);
    }
}

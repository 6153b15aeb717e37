//! The bench tests of the paper (section 4) and the figures read from them.
//!
//! * **Static test**: the belt, formed into a circle of circumference L, is
//!   put on the floor and settles under its own weight
//!   ([`static_test`]): `Hs` is the height of the outer surface at A, `Ws`
//!   the overall width of the outer surface.
//! * **Dynamic test**: a 1.3 kg roller is put on A at rest
//!   ([`dynamic_test`]); A oscillates and settles. `T` and `Λ` come from
//!   the first two maxima of A's height about the settled height
//!   ([`crate::figures`]); `Hd`, `Wd` are the settled values (the
//!   equilibrium the motion decays to, solved from the state at the end of
//!   the run); the joint-angle ranges at A and at C (the side joint bent
//!   furthest) are tracked over the whole run (the paper's Tables 3, 5, 7).
//!
//! Heights and widths are read on the outer surface, half the thickness off
//! the link axis: the centre line would shift them by 4–8 mm.

use crate::bushing::BushingChain;
use crate::chain::Chain;
use crate::error::{invalid, Result};
use crate::figures::{period_and_decrement, PeakTracker};
use crate::integrator;
use crate::real::Real;

/// Figures of the static test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticFigures {
    /// Height of A's outer surface above the floor, mm.
    pub hs_mm: f64,
    /// Overall width, mm.
    pub ws_mm: f64,
}

/// Figures of the dynamic test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynamicFigures {
    /// Settled height of A, mm.
    pub hd_mm: f64,
    /// Settled width, mm.
    pub wd_mm: f64,
    /// Period of A's vertical oscillation, s (`None`: fewer than two maxima).
    pub period_s: Option<f64>,
    /// Logarithmic decrement of the first two maxima.
    pub log_decrement: Option<f64>,
    /// Joint-angle range at A over the run, degrees `[min, max]`.
    pub angle_a_deg: [f64; 2],
    /// Joint-angle range at C (the joint bent furthest), degrees.
    pub angle_c_deg: [f64; 2],
    /// Index of joint C (0 is A, counted clockwise).
    pub joint_c: usize,
    /// Lowest height of A during the run, mm.
    pub min_height_mm: f64,
}

/// All bench figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BenchFigures {
    /// Static test.
    pub static_test: StaticFigures,
    /// Dynamic test.
    pub dynamic_test: DynamicFigures,
}

/// The dynamic test's set-up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynamicTest<T> {
    /// Roller mass, kg (paper: 1.3).
    pub roller_kg: T,
    /// Simulated time after the roller is put on, s.
    pub duration_s: T,
}

impl<T: Real> Default for DynamicTest<T> {
    fn default() -> Self {
        DynamicTest {
            roller_kg: T::from_f64(1.3),
            duration_s: T::from_f64(5.0),
        }
    }
}

/// What the bench scenarios need from a belt model: implemented by the pin
/// chain ([`Chain`]) and the bushing chain ([`BushingChain`]), so both run
/// the same scenario code. `D` bounds the number of joints (the chain's
/// capacity).
pub trait BenchChain<T: Real, const D: usize> {
    /// Number of links (and joints).
    fn links(&self) -> usize;
    /// Attach (or, with 0, remove) the roller's point mass at A, kg.
    fn set_roller_mass(&mut self, kg: T) -> Result<()>;
    /// Lay the belt out as a circle at rest on the floor.
    fn set_circle_on_floor(&mut self);
    /// Settle to the nearest static equilibrium, at rest.
    fn solve_static(&mut self) -> Result<usize>;
    /// Zero the velocities and forget the integrator history.
    fn reset_motion(&mut self);
    /// Set the simulated time, s.
    fn set_time(&mut self, t: T);
    /// Simulated time, s.
    fn time_s(&self) -> T;
    /// Smallest step before a run is declared diverged, s.
    fn min_step_s(&self) -> T;
    /// Advance by one step of at most `h_max`, s.
    fn step_max(&mut self, h_max: T) -> Result<()>;
    /// Joint angle at joint `j`, rad.
    fn joint_angle(&self, j: usize) -> T;
    /// Height of the outer surface at A, m.
    fn a_height_m(&self) -> T;
    /// Overall width of the outer surface, m.
    fn width_m(&self) -> T;
    /// Kinetic plus potential energy, J, if the model can tell (the
    /// validity checks: without external work it can only fall).
    fn mechanical_energy_j(&self) -> Option<T> {
        None
    }
    /// Kinetic energy, J, if the model can tell.
    fn kinetic_energy_j(&self) -> Option<T> {
        None
    }
    /// Largest speed of any joint, m/s, if the model can tell.
    fn max_joint_speed_m_s(&self) -> Option<T> {
        None
    }
    /// Power the joints' damping dissipates, W, if the model can tell.
    fn joint_damping_power_w(&self) -> Option<T> {
        None
    }
    /// Closure constraint residuals `(position m, velocity m/s)`, for a
    /// model with a closure constraint.
    fn closure_residuals(&self) -> Option<(T, T)> {
        None
    }
    /// `(force, closure)`: how far the present state, at rest, is from a
    /// static equilibrium (see [`Chain::static_imbalance`]), if the model
    /// can tell. Changes nothing.
    fn static_imbalance(&mut self) -> Option<(f64, f64)> {
        None
    }
    /// Solver counters, if the model keeps them.
    fn solver_stats(&self) -> Option<crate::integrator::Stats> {
        None
    }
}

macro_rules! bench_chain {
    ($ty:ident { $($extra:tt)* }) => {
        impl<T: Real, const D: usize> BenchChain<T, D> for $ty<T, D> {
            fn links(&self) -> usize {
                $ty::links(self)
            }
            fn set_roller_mass(&mut self, kg: T) -> Result<()> {
                $ty::set_roller_mass(self, kg)
            }
            fn set_circle_on_floor(&mut self) {
                $ty::set_circle_on_floor(self)
            }
            fn solve_static(&mut self) -> Result<usize> {
                $ty::solve_static(self)
            }
            fn reset_motion(&mut self) {
                $ty::reset_motion(self)
            }
            fn set_time(&mut self, t: T) {
                $ty::set_time(self, t)
            }
            fn time_s(&self) -> T {
                $ty::time_s(self)
            }
            fn min_step_s(&self) -> T {
                self.settings.min_step_s
            }
            fn step_max(&mut self, h_max: T) -> Result<()> {
                $ty::step_max(self, h_max)
            }
            fn joint_angle(&self, j: usize) -> T {
                $ty::joint_angle(self, j)
            }
            fn a_height_m(&self) -> T {
                $ty::a_height_m(self)
            }
            fn width_m(&self) -> T {
                $ty::width_m(self)
            }
            fn mechanical_energy_j(&self) -> Option<T> {
                Some($ty::mechanical_energy_j(self))
            }
            fn kinetic_energy_j(&self) -> Option<T> {
                Some($ty::kinetic_energy_j(self))
            }
            fn max_joint_speed_m_s(&self) -> Option<T> {
                Some($ty::max_joint_speed_m_s(self))
            }
            fn static_imbalance(&mut self) -> Option<(f64, f64)> {
                Some($ty::static_imbalance(self))
            }
            fn solver_stats(&self) -> Option<crate::integrator::Stats> {
                Some($ty::stats(self))
            }
            $($extra)*
        }
    };
}
bench_chain! {
    Chain {
        fn joint_damping_power_w(&self) -> Option<T> {
            Some(Chain::joint_damping_power_w(self))
        }
        fn closure_residuals(&self) -> Option<(T, T)> {
            Some(Chain::closure_residuals(self))
        }
    }
}
bench_chain! { BushingChain {} }

/// Static test: circle on the floor, settle, read Hs and Ws.
pub fn static_test<T: Real, const D: usize, C: BenchChain<T, D>>(
    chain: &mut C,
) -> Result<StaticFigures> {
    chain.set_roller_mass(T::ZERO)?;
    chain.set_circle_on_floor();
    chain.solve_static()?;
    Ok(StaticFigures {
        hs_mm: chain.a_height_m().to_f64() * 1e3,
        ws_mm: chain.width_m().to_f64() * 1e3,
    })
}

/// Dynamic test from the current (settled) state: put the roller on A, run
/// for `test.duration_s`, calling `observe` after every step, then solve
/// the settled state.
pub fn dynamic_test<T: Real, const D: usize, C: BenchChain<T, D>, F: FnMut(&C)>(
    chain: &mut C,
    test: &DynamicTest<T>,
    mut observe: F,
) -> Result<DynamicFigures> {
    if !test.duration_s.is_finite() || test.duration_s <= T::ZERO {
        return Err(invalid("dynamic.duration_s", "must be positive and finite"));
    }
    chain.set_roller_mass(test.roller_kg)?;
    chain.reset_motion();
    chain.set_time(T::ZERO);
    let n = chain.links();
    let mut lo = [f64::INFINITY; D];
    let mut hi = [f64::NEG_INFINITY; D];
    let n = n.min(D);
    let track = |chain: &C, lo: &mut [f64; D], hi: &mut [f64; D]| {
        for j in 0..n {
            let z = chain.joint_angle(j).to_f64();
            lo[j] = lo[j].min(z);
            hi[j] = hi[j].max(z);
        }
    };
    track(chain, &mut lo, &mut hi);
    let mut peaks = PeakTracker::new();
    let mut min_h = chain.a_height_m().to_f64();
    peaks.push(0.0, min_h);
    observe(chain);
    let end = test.duration_s.to_f64();
    let min_step = chain.min_step_s();
    integrator::step_until(
        chain,
        end,
        min_step.to_f64(),
        "bench dynamic test (step budget)",
        |chain| chain.time_s().to_f64(),
        |chain, _| {
            let left = T::from_f64(end) - chain.time_s();
            chain.step_max(left.max(min_step))?;
            let h = chain.a_height_m().to_f64();
            peaks.push(chain.time_s().to_f64(), h);
            min_h = min_h.min(h);
            track(chain, &mut lo, &mut hi);
            observe(chain);
            Ok(())
        },
    )?;
    // Settled state: the equilibrium the motion decays to.
    chain.solve_static()?;
    let hd = chain.a_height_m().to_f64();
    let wd = chain.width_m().to_f64();
    let mut joint_c = 1;
    for j in 1..n {
        if lo[j] < lo[joint_c] {
            joint_c = j;
        }
    }
    let (period, lam) = match period_and_decrement(peaks.maxima(), hd) {
        Some((t, l)) => (Some(t), Some(l)),
        None => (None, None),
    };
    let deg = 180.0 / core::f64::consts::PI;
    Ok(DynamicFigures {
        hd_mm: hd * 1e3,
        wd_mm: wd * 1e3,
        period_s: period,
        log_decrement: lam,
        angle_a_deg: [lo[0] * deg, hi[0] * deg],
        angle_c_deg: [lo[joint_c] * deg, hi[joint_c] * deg],
        joint_c,
        min_height_mm: min_h * 1e3,
    })
}

/// Both tests in sequence.
pub fn run<T: Real, const D: usize, C: BenchChain<T, D>, F: FnMut(&C)>(
    chain: &mut C,
    test: &DynamicTest<T>,
    observe: F,
) -> Result<BenchFigures> {
    let s = static_test(chain)?;
    let d = dynamic_test(chain, test, observe)?;
    Ok(BenchFigures {
        static_test: s,
        dynamic_test: d,
    })
}

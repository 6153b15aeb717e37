//! Forward models the diagnosis fits and the generator samples: A's
//! height in the dynamic test, the rig's drive torque along a speed and
//! temperature profile, and linear interpolation of their traces.

use crate::error::{Error, Result};
use crate::sim::{with_sized_chain, ChainRun};
use crate::validity::Monitor;
use trackbelt::bench::{self, DynamicTest};
use trackbelt::joint::JointLaw;
use trackbelt::params::Belt;
use trackbelt::rig::{Rig, RigConfig};
use trackbelt::{Chain, Settings};

/// The forward model's validity checks take the energy balance, the
/// closure and the joint speeds every this many steps
/// ([`Monitor::sampling_every`]): a diagnosis simulates a thousand times,
/// and taken every step they cost a quarter of each run.
pub const MONITOR_STRIDE: usize = 4;

/// A's height (mm) against time (s) in the dynamic test of `law`: static
/// settle, roller on, `duration_s` of motion. A run that fails a validity
/// check ([`crate::validity`]) is an error; its warnings are dropped (see
/// [`simulate_height_checked`]).
pub fn simulate_height(
    law: &JointLaw<f64>,
    belt: &Belt<f64>,
    roller_kg: f64,
    duration_s: f64,
) -> Result<Vec<(f64, f64)>> {
    simulate_height_checked(law, belt, roller_kg, duration_s).map(|(t, _)| t)
}

/// A's height against time, `(t s, mm)`.
pub type HeightTrace = Vec<(f64, f64)>;

/// [`simulate_height`] with the validity warnings of the run
/// (`"<check>: <value>"`).
pub fn simulate_height_checked(
    law: &JointLaw<f64>,
    belt: &Belt<f64>,
    roller_kg: f64,
    duration_s: f64,
) -> Result<(HeightTrace, Vec<String>)> {
    let model = trackbelt::params::Model::new(*belt, law.clone())?;
    let settings = Settings {
        relax_creep_steps: RELAX_CREEP_STEPS,
        ..Settings::default()
    };
    with_sized_chain(
        model,
        settings,
        HeightRun {
            roller_kg,
            duration_s,
        },
    )
}

/// [`simulate_height_checked`]'s run ([`height_run`]).
struct HeightRun {
    roller_kg: f64,
    duration_s: f64,
}

impl ChainRun for HeightRun {
    type Output = (HeightTrace, Vec<String>);
    fn run<const D: usize>(self, chain: &mut Chain<f64, D>) -> Result<Self::Output> {
        height_run(chain, self.roller_kg, self.duration_s)
    }
}

/// The forward model's settle after the dynamic test ends its relaxation
/// once the belt has crept this many steps from rest
/// ([`Settings::relax_creep_steps`]): on the shipped E38 table the
/// relaxation otherwise ran all its 3000 steps, a fifth of the run. The
/// trace is the same; only the settled state the validity checks read
/// moves, within the static solver's tolerance.
pub const RELAX_CREEP_STEPS: usize = 200;

/// The dynamic test's run behind [`simulate_height_checked`].
fn height_run<const D: usize>(
    chain: &mut Chain<f64, D>,
    roller_kg: f64,
    duration_s: f64,
) -> Result<(HeightTrace, Vec<String>)> {
    let mut monitor = Monitor::sampling_every(MONITOR_STRIDE);
    bench::static_test(chain)?;
    monitor.after_static(chain);
    let mut trace = Vec::with_capacity(4096);
    let test = DynamicTest {
        roller_kg,
        duration_s,
    };
    let d = bench::dynamic_test(chain, &test, |c| {
        trace.push((c.time_s(), c.a_height_m() * 1e3));
        monitor.observe(c);
    })?;
    monitor.after_dynamic(chain, &d);
    let warnings = monitor.validity().check()?;
    Ok((trace, warnings))
}

/// Linear interpolation of a trace (times increasing) at `times`; the ends
/// are held.
pub fn interpolate(trace: &[(f64, f64)], times: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(times.len());
    let mut i = 0;
    for &t in times {
        while i + 1 < trace.len() && trace[i + 1].0 < t {
            i += 1;
        }
        let v = match (trace.get(i), trace.get(i + 1)) {
            (Some(&(t0, y0)), Some(&(t1, y1))) if t1 > t0 => {
                let w = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
                y0 + w * (y1 - y0)
            }
            (Some(&(_, y0)), _) => y0,
            _ => f64::NAN,
        };
        out.push(v);
    }
    out
}

/// Piecewise-linear interpolation through `knots` (held at the ends).
pub fn knots_at(knots: &[(f64, f64)], t: f64) -> f64 {
    interpolate(knots, &[t]).first().copied().unwrap_or(0.0)
}

/// Drive the rig along `omega(t)` (rad/s) with the belt at `temp(t)` (°C)
/// for `duration_s`: `(t s, ω rad/s, drive torque N·m)` after every step.
pub fn simulate_scroll(
    law: &JointLaw<f64>,
    belt: &Belt<f64>,
    config: &RigConfig<f64>,
    omega: &dyn Fn(f64) -> f64,
    temp: &dyn Fn(f64) -> f64,
    duration_s: f64,
) -> Result<Vec<(f64, f64, f64)>> {
    let model = trackbelt::params::Model::new(*belt, law.clone())?;
    let max_speed = crate::rig::max_speed_rad_s(&model, config);
    let settings = crate::rig::rig_settings();
    let mut rig: Box<Rig<f64, { crate::rig::RIG_CAPACITY }>> =
        Box::new(Rig::new(model, *config, settings)?);
    let t0 = rig.time_s();
    let h = settings.step_s;
    let mut out = Vec::with_capacity((duration_s / h) as usize + 8);
    let max_steps = (duration_s / settings.min_step_s).min(1e8) as u64 + 1;
    let mut steps = 0u64;
    loop {
        let t = rig.time_s() - t0;
        if t >= duration_s - 1e-12 {
            break;
        }
        steps += 1;
        if steps > max_steps {
            return Err(Error::StepBudget("scroll simulation"));
        }
        let dt = h.min(duration_s - t);
        let w = omega(t + dt);
        if w.is_nan() || w.abs() > max_speed {
            return Err(Error::RigInvalid {
                check: "drive speed",
                value: w,
                limit: format!(
                    "valid up to ±{max_speed:.1} rad/s (at t = {:.3} s of the profile): faster, a \
                     link passes the drive in fewer than {} time steps",
                    t + dt,
                    crate::rig::MIN_STEPS_PER_LINK
                ),
            });
        }
        rig.set_drive_speed(w)?;
        rig.set_belt_temperature_c(temp(t + dt))?;
        rig.step_max(dt)?;
        out.push((
            rig.time_s() - t0,
            rig.drive_speed_rad_s(),
            rig.drive_torque_nm(),
        ));
    }
    Ok(out)
}

//! Estimator soak: one hour at 1 kHz (3.6 M updates) of a drive profile
//! (accelerations, cruise, reversals, stops) with injected glitches (NaN,
//! ±inf, dropouts, zero and negative ticks, 100× speed jumps), run in f32
//! and in 32.32 fixed point against the f64 estimator on the same table
//! (the shipped `params/E56.toml`).
//!
//! Checked:
//! * every output is finite, in every number type;
//! * the flags are set on every glitch: `SPEED_NOT_FINITE` on NaN/±inf,
//!   `BAD_TICK` on a zero or negative tick, `SPEED_OUT_OF_RANGE` on a jump
//!   beyond the table; none on a good sample (all inside the table);
//! * recovery on the first good sample: the bending loss there equals the
//!   glitch-free run's (the state holds no bending memory); the inertia
//!   term differences two speeds, so the torque equals the glitch-free
//!   run's from the second good sample on (and on the first after a
//!   dropout, which comes with its true tick);
//! * no drift from the f64 estimator fed the same (narrow-type) inputs:
//!   relative error ≤ 1e-4 on every good sample over the hour, relative to
//!   `max(|τ_f64|, 0.01 N·m)`, and no growth between the first and last
//!   ten minutes.
//!
//! Runs in CI in release mode (a few seconds); in debug it runs a tenth of
//! the hour.

use trackbelt::estimator::{EstimatorState, EstimatorTable, Status};
use trackbelt::{Fx, Real};

const RATE_HZ: f64 = 1000.0;

fn updates() -> usize {
    if cfg!(debug_assertions) {
        360_000
    } else {
        3_600_000
    }
}

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// The drive profile: segments of smooth (cosine) ramps to a new target
/// speed — faster, slower, reversed or stopped — each followed by a cruise
/// or a standstill. Speeds within ±12 rad/s (the table covers 15).
fn profile(n: usize, rng: &mut Rng) -> Vec<f64> {
    let mut out = Vec::with_capacity(n);
    let mut w = 0.0f64;
    while out.len() < n {
        let r = rng.unit();
        let target = if r < 0.15 {
            0.0 // stop
        } else if r < 0.35 {
            let dir = if w < 0.0 { 1.0 } else { -1.0 };
            dir * rng.range(1.0, 12.0) // reversal
        } else {
            // Faster or slower, same direction.
            let dir = if w < 0.0 { -1.0 } else { 1.0 };
            dir * rng.range(0.2, 12.0)
        };
        let ramp = (rng.range(0.2, 5.0) * RATE_HZ) as usize;
        for k in 0..ramp {
            let s = 0.5 - 0.5 * (std::f64::consts::PI * (k + 1) as f64 / ramp as f64).cos();
            out.push(w + (target - w) * s);
        }
        w = target;
        let hold = (rng.range(0.5, 30.0) * RATE_HZ) as usize;
        out.extend(std::iter::repeat_n(w, hold));
    }
    out.truncate(n);
    out
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Glitch {
    None,
    Nan,
    PosInf,
    NegInf,
    /// The sample is lost: no update; the next comes with twice the tick.
    Dropout,
    ZeroTick,
    NegativeTick,
    Jump100,
}

/// One input of the run: speed, tick and what it is.
#[derive(Debug, Clone, Copy)]
struct Input {
    speed: f64,
    dt: f64,
    glitch: Glitch,
}

/// The glitched input stream (about 1 sample in 500 is a glitch, in bursts
/// of one to three). Dropped samples are not in it.
fn inputs(speeds: &[f64], rng: &mut Rng) -> Vec<Input> {
    let dt = 1.0 / RATE_HZ;
    let mut out = Vec::with_capacity(speeds.len());
    let mut pending_dt = dt;
    let mut burst = 0u32;
    let mut kind = Glitch::None;
    for &w in speeds {
        if burst == 0 && rng.unit() < 0.002 {
            burst = 1 + (rng.next() % 3) as u32;
            kind = match rng.next() % 7 {
                0 => Glitch::Nan,
                1 => Glitch::PosInf,
                2 => Glitch::NegInf,
                3 => Glitch::Dropout,
                4 => Glitch::ZeroTick,
                5 => Glitch::NegativeTick,
                _ => Glitch::Jump100,
            };
        }
        let g = if burst > 0 {
            burst -= 1;
            kind
        } else {
            Glitch::None
        };
        let input = match g {
            Glitch::None => Input {
                speed: w,
                dt: pending_dt,
                glitch: g,
            },
            Glitch::Nan => Input {
                speed: f64::NAN,
                dt,
                glitch: g,
            },
            Glitch::PosInf => Input {
                speed: f64::INFINITY,
                dt,
                glitch: g,
            },
            Glitch::NegInf => Input {
                speed: f64::NEG_INFINITY,
                dt,
                glitch: g,
            },
            Glitch::Dropout => {
                pending_dt += dt;
                continue;
            }
            Glitch::ZeroTick => Input {
                speed: w,
                dt: 0.0,
                glitch: g,
            },
            Glitch::NegativeTick => Input {
                speed: w,
                dt: -dt,
                glitch: g,
            },
            Glitch::Jump100 => {
                // 100× the speed, at least 50 rad/s: beyond the table.
                let j = 100.0 * w;
                let j = if j.abs() < 50.0 {
                    50.0f64.copysign(if w == 0.0 { 1.0 } else { w })
                } else {
                    j
                };
                Input {
                    speed: j,
                    dt,
                    glitch: g,
                }
            }
        };
        if g == Glitch::None {
            pending_dt = dt;
        }
        out.push(input);
    }
    out
}

fn table() -> EstimatorTable<f64> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../params/E56.toml");
    trackbelt_host::firmware::estimator_table(&path)
        .expect("E56 table")
        .table
}

/// Figures of one narrow-type run.
#[derive(Debug, Default)]
struct Soak {
    updates: usize,
    good: usize,
    glitches: usize,
    max_rel: f64,
    max_rel_first_10min: f64,
    max_rel_last_10min: f64,
    recovery_checks: usize,
}

/// Runs `T` and f64 side by side on `inputs` (each input rounded to `T`
/// once; the f64 estimator gets the rounded value), with a glitch-free
/// f64 run for the recovery check.
fn soak<T: Real>(table64: &EstimatorTable<f64>, inputs: &[Input]) -> Soak {
    let table_t = table64.cast::<T>();
    // The f64 reference runs on the table cast back from T, so both run the
    // same coefficients: only the arithmetic differs.
    let table_ref: EstimatorTable<f64> = table_t.cast::<f64>();
    let mut st_t = EstimatorState::<T>::new();
    let mut st_64 = EstimatorState::<f64>::new();
    let mut st_clean = EstimatorState::<f64>::new();
    let mut s = Soak::default();
    let n = inputs.len();
    let ten_min = (600.0 * RATE_HZ) as usize;
    let mut since_glitch = usize::MAX; // good samples since the last glitch
    let mut last_glitch = Glitch::None;
    for (i, inp) in inputs.iter().enumerate() {
        let (w_t, dt_t) = (T::from_f64(inp.speed), T::from_f64(inp.dt));
        // (A saturated fixed-point value is not finite: the f64 run then
        // gets the original, non-finite, input too.)
        let narrow = |x: T, orig: f64| if x.is_finite() { x.to_f64() } else { orig };
        let (w, dt) = (narrow(w_t, inp.speed), narrow(dt_t, inp.dt));
        let e_t = table_t.update(&mut st_t, w_t, dt_t);
        let e_64 = table_ref.update(&mut st_64, w, dt);
        s.updates += 1;
        let (tq, bd) = (e_t.torque_nm.to_f64(), e_t.bending_nm.to_f64());
        assert!(
            tq.is_finite() && bd.is_finite(),
            "update {i}: {inp:?} → {e_t:?}"
        );
        assert!(e_64.torque_nm.is_finite() && e_64.bending_nm.is_finite());
        match inp.glitch {
            Glitch::None => {
                assert!(
                    e_t.status.is_ok(),
                    "update {i}: good sample {inp:?} flagged {:?}",
                    e_t.status
                );
                s.good += 1;
                let e_clean = table_ref.update(&mut st_clean, w, dt);
                let scale = e_64.torque_nm.abs().max(0.01);
                let rel = (tq - e_64.torque_nm).abs() / scale;
                let rel_b = (bd - e_64.bending_nm).abs() / e_64.bending_nm.abs().max(0.01);
                let rel = rel.max(rel_b);
                assert!(
                    rel <= 1e-4,
                    "update {i}: {tq} vs f64 {} (rel {rel:e})",
                    e_64.torque_nm
                );
                s.max_rel = s.max_rel.max(rel);
                if i < ten_min {
                    s.max_rel_first_10min = s.max_rel_first_10min.max(rel);
                }
                if i + ten_min >= n {
                    s.max_rel_last_10min = s.max_rel_last_10min.max(rel);
                }
                // Recovery: bending at once; torque from the second good
                // sample (at once after a dropout, which has its true tick).
                since_glitch = since_glitch.saturating_add(1);
                if since_glitch < 3 {
                    s.recovery_checks += 1;
                    let tol = 1e-4 * e_clean.torque_nm.abs().max(0.01);
                    assert!(
                        (bd - e_clean.bending_nm).abs()
                            <= 1e-4 * e_clean.bending_nm.abs().max(0.01),
                        "update {i}: bending {bd} vs clean {} after {last_glitch:?}",
                        e_clean.bending_nm
                    );
                    if since_glitch == 2 || last_glitch == Glitch::Dropout {
                        assert!(
                            (tq - e_clean.torque_nm).abs() <= tol,
                            "update {i}: torque {tq} vs clean {} after {last_glitch:?}",
                            e_clean.torque_nm
                        );
                    }
                }
            }
            g => {
                s.glitches += 1;
                since_glitch = 0;
                last_glitch = g;
                let need = match g {
                    Glitch::Nan | Glitch::PosInf | Glitch::NegInf => Status::SPEED_NOT_FINITE,
                    Glitch::ZeroTick | Glitch::NegativeTick => Status::BAD_TICK,
                    Glitch::Jump100 => Status::SPEED_OUT_OF_RANGE,
                    Glitch::None | Glitch::Dropout => unreachable!(),
                };
                // Fixed point saturates ±inf to its range: still flagged
                // as not finite (a saturated value is not finite).
                assert!(
                    e_t.status.contains(need),
                    "update {i}: {inp:?} → {:?}",
                    e_t.status
                );
                if g == Glitch::Dropout {
                    unreachable!();
                }
                if matches!(g, Glitch::ZeroTick | Glitch::NegativeTick) {
                    // The clean run sees the same speed with a good tick.
                    let _ = table_ref.update(&mut st_clean, w, 1.0 / RATE_HZ);
                }
            }
        }
        // A dropout marks the next good sample as "after a glitch".
        if i + 1 < n && inputs[i + 1].glitch == Glitch::None && inputs[i + 1].dt > 1.5 / RATE_HZ {
            since_glitch = 0;
            last_glitch = Glitch::Dropout;
        }
    }
    s
}

fn run<T: Real>(name: &str) {
    let start = std::time::Instant::now();
    let mut rng = Rng(0x5eed_1234_abcd_0001);
    // A little more than the hour of samples, so that the updates (the
    // dropped samples are not updates) make the full hour.
    let speeds = profile(updates() + updates() / 100, &mut rng);
    let mut inputs = inputs(&speeds, &mut rng);
    inputs.truncate(updates());
    let table = table();
    let s = soak::<T>(&table, &inputs);
    println!(
        "soak {name}: {} updates ({} good, {} glitches, {} good samples after a dropout), max relative error vs f64 {:.2e} \
         (first 10 min {:.2e}, last 10 min {:.2e}), {} recovery checks, {:.2} s",
        s.updates,
        s.good,
        s.glitches,
        inputs.iter().filter(|i| i.dt > 1.5 / RATE_HZ).count(),
        s.max_rel,
        s.max_rel_first_10min,
        s.max_rel_last_10min,
        s.recovery_checks,
        start.elapsed().as_secs_f64()
    );
    assert_eq!(s.updates, updates());
    assert!(s.glitches > 1000, "too few glitches: {}", s.glitches);
    assert!(s.max_rel <= 1e-4);
    // No growth over the hour: the last ten minutes are no worse than the
    // first (within the bound's resolution).
    assert!(s.max_rel_last_10min <= s.max_rel_first_10min.max(1e-6) * 10.0);
}

#[test]
fn soak_f32() {
    run::<f32>("f32");
}

#[test]
fn soak_fixed_point() {
    run::<Fx>("Fx");
}

//! The embedded number types against the f64 reference build: bench
//! figures and host wall time per build.
//!
//! ```sh
//! cargo run --release -p trackbelt-host-tests --example number_types [-- --repeat 3]
//! ```
//!
//! Prints, for E38/E56/E76 and methods I and II, Hs, Hd, T of each build,
//! the differences against f64, and the best wall time of the static test
//! and of the dynamic test (5 s simulated) over `--repeat` runs.

use std::time::{Duration, Instant};
use trackbelt::bench::{self, DynamicTest};
use trackbelt::params::{Method, Model, Variant};
use trackbelt::{Chain, Fx, Real, Settings};

const CAP: usize = 80;

#[derive(Clone, Copy)]
struct Outcome {
    hs_mm: f64,
    hd_mm: f64,
    period_s: f64,
    static_time: Duration,
    dynamic_time: Duration,
}

fn run<T: Real>(variant: Variant, method: Method, repeat: usize) -> Result<Outcome, String> {
    let mut best: Option<Outcome> = None;
    for _ in 0..repeat.max(1) {
        let model: Model<T> = Model::<f64>::paper(variant, method)
            .map_err(|e| e.to_string())?
            .cast();
        let mut chain =
            Box::new(Chain::<T, CAP>::new(model, Settings::default()).map_err(|e| e.to_string())?);
        let t0 = Instant::now();
        let s = bench::static_test(&mut *chain).map_err(|e| format!("static: {e}"))?;
        let t1 = Instant::now();
        let d = bench::dynamic_test(&mut *chain, &DynamicTest::default(), |_| {})
            .map_err(|e| format!("dynamic: {e}"))?;
        let t2 = Instant::now();
        let o = Outcome {
            hs_mm: s.hs_mm,
            hd_mm: d.hd_mm,
            period_s: d.period_s.unwrap_or(f64::NAN),
            static_time: t1 - t0,
            dynamic_time: t2 - t1,
        };
        best = Some(match best {
            Some(b) if b.static_time + b.dynamic_time <= o.static_time + o.dynamic_time => b,
            _ => o,
        });
    }
    best.ok_or_else(|| "no run".into())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let repeat = match args.iter().position(|a| a == "--repeat") {
        Some(i) => match args.get(i + 1).and_then(|s| s.parse().ok()) {
            Some(n) => n,
            None => {
                eprintln!("error: --repeat needs a positive integer");
                std::process::exit(2);
            }
        },
        None => 1,
    };
    println!("build   var  method  Hs mm     dHs      Hd mm     dHd      T s      dT %     static ms  dynamic ms");
    let mut failed = false;
    for method in [Method::I, Method::II] {
        for variant in Variant::ALL {
            let reference = match run::<f64>(variant, method, repeat) {
                Ok(r) => r,
                Err(e) => {
                    eprintln!("error: f64 {variant:?} method {method:?}: {e}");
                    failed = true;
                    continue;
                }
            };
            let builds: [(&str, Result<Outcome, String>); 3] = [
                ("f64", Ok(reference)),
                ("f32", run::<f32>(variant, method, repeat)),
                ("I32F32", run::<Fx>(variant, method, repeat)),
            ];
            for (name, r) in builds {
                match r {
                    Ok(o) => println!(
                        "{name:7} {:4} {:7} {:8.3} {:+7.3}  {:8.3} {:+7.3}  {:7.4} {:+7.2}   {:9.1}  {:10.1}",
                        format!("{variant:?}"),
                        format!("{method:?}"),
                        o.hs_mm,
                        o.hs_mm - reference.hs_mm,
                        o.hd_mm,
                        o.hd_mm - reference.hd_mm,
                        o.period_s,
                        (o.period_s / reference.period_s - 1.0) * 100.0,
                        o.static_time.as_secs_f64() * 1e3,
                        o.dynamic_time.as_secs_f64() * 1e3,
                    ),
                    Err(e) => {
                        eprintln!("error: {name} {variant:?} method {method:?}: {e}");
                        failed = true;
                    }
                }
            }
        }
    }
    if failed {
        std::process::exit(1);
    }
}

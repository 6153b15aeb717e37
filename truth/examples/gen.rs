//! `gen OUTCOME KIND SEED DIR [MAGNITUDE|-] [RUNS]`: write one dataset
//! (RUNS runs of its belt, default 1) and print its truth.
use trackbelt_truth::*;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 5 {
        eprintln!("usage: gen OUTCOME dynamic|scroll SEED DIR [MAGNITUDE|-] [RUNS]");
        std::process::exit(2);
    }
    let Some(outcome) = Outcome::from_name(&a[1]) else {
        eprintln!("gen: unknown outcome {}", a[1]);
        std::process::exit(2);
    };
    let kind = if a[2] == "scroll" {
        SeriesKind::Scroll
    } else {
        SeriesKind::Dynamic
    };
    let seed: u64 = a[3].parse().unwrap();
    let sc = match a.get(5).filter(|m| m.as_str() != "-") {
        Some(m) => draw_at(outcome, kind, seed, m.parse().unwrap()),
        None => draw(outcome, kind, seed),
    }
    .unwrap();
    let runs: u32 = a.get(6).map_or(1, |r| r.parse().unwrap());
    let runs: Vec<_> = (0..runs).map(|r| sc.repeat(r)).collect();
    let t0 = std::time::Instant::now();
    let truth = match generate_runs(&runs, std::path::Path::new(&a[4])) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("{}: {e}", a[4]);
            std::process::exit(1);
        }
    };
    println!(
        "{}\texpected={}\tN={}\th={:.2e}\tnoise={:.3} {}\t{:?}\twall={:.2}s\t{}",
        a[4],
        truth.expected,
        truth.nodes,
        truth.step_s,
        truth.noise_rms,
        truth.noise_unit,
        truth.figures,
        t0.elapsed().as_secs_f64(),
        truth.description
    );
}

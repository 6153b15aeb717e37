//! `rival EFFECT RIVAL dynamic|scroll SEED [SEED…]`: the rival ceiling
//! ([`trackbelt_truth::ceiling::rival_ceiling`]) of each seed's dataset
//! of EFFECT against RIVAL, one tab-separated line each: effect, rival,
//! kind, seed, magnitude, samples, σ, Δχ² against the rival's twin as
//! drawn, the rival ceiling, the twin's EI, curvature and damping
//! factors, and the rival's fitted law.
use trackbelt_truth::ceiling::rival_ceiling;
use trackbelt_truth::*;

fn effect(name: &str) -> EffectKind {
    match EffectKind::from_name(name) {
        Some(e) => e,
        None => {
            eprintln!("unknown effect {name}");
            std::process::exit(2);
        }
    }
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 5 {
        eprintln!("usage: rival EFFECT RIVAL dynamic|scroll SEED [SEED…]");
        std::process::exit(2);
    }
    let (e, r) = (effect(&a[1]), effect(&a[2]));
    let kind = if a[3] == "scroll" {
        SeriesKind::Scroll
    } else {
        SeriesKind::Dynamic
    };
    let scratch = std::env::temp_dir().join(format!("rival-{}", std::process::id()));
    let mut failed = false;
    for s in &a[4..] {
        let Ok(seed) = s.parse::<u64>() else {
            eprintln!("{s}: not a seed");
            std::process::exit(2);
        };
        let line = draw(Outcome::Effect(e), kind, seed).and_then(|sc| {
            rival_ceiling(&sc, r, &scratch).map(|c| {
                format!(
                    "{}\t{}\t{}\t{seed}\t{:.3}\t{}\t{:.4}\t{:.1}\t{:.1}\t{:.3}\t{:.3}\t{:.3}\t{}",
                    e.as_str(),
                    r.as_str(),
                    kind.as_str(),
                    sc.magnitude,
                    c.samples,
                    c.sigma,
                    c.chi2_start,
                    c.chi2,
                    c.factors[0],
                    c.factors[1],
                    c.factors[2],
                    c.rival_law
                )
            })
        });
        match line {
            Ok(l) => println!("{l}"),
            Err(err) => {
                eprintln!("{} vs {} seed {seed}: {err}", e.as_str(), r.as_str());
                failed = true;
            }
        }
    }
    if failed {
        std::process::exit(1);
    }
}

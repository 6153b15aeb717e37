//! `oracle EFFECT dynamic|scroll SEED [SEED…]`: the evidence ceiling
//! ([`trackbelt_truth::ceiling`]) of each seed's dataset, one
//! tab-separated line each: effect, kind, seed, magnitude, samples, σ,
//! Δχ² against the clean twin as it is, the ceiling (Δχ² against the
//! best-scaled twin), and the twin's EI, curvature and damping factors.
use trackbelt_truth::ceiling::ceiling;
use trackbelt_truth::*;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 4 {
        eprintln!("usage: oracle EFFECT dynamic|scroll SEED [SEED…]");
        std::process::exit(2);
    }
    let Some(effect) = EffectKind::from_name(&a[1]) else {
        eprintln!("unknown effect {}", a[1]);
        std::process::exit(2);
    };
    let kind = if a[2] == "scroll" {
        SeriesKind::Scroll
    } else {
        SeriesKind::Dynamic
    };
    let scratch = std::env::temp_dir().join(format!("oracle-{}", std::process::id()));
    let mut failed = false;
    for s in &a[3..] {
        let Ok(seed) = s.parse::<u64>() else {
            eprintln!("{s}: not a seed");
            std::process::exit(2);
        };
        let line = draw(Outcome::Effect(effect), kind, seed).and_then(|sc| {
            ceiling(&sc, &scratch).map(|c| {
                format!(
                    "{}\t{}\t{seed}\t{:.3}\t{}\t{:.4}\t{:.1}\t{:.1}\t{:.3}\t{:.3}\t{:.3}",
                    effect.as_str(),
                    kind.as_str(),
                    sc.magnitude,
                    c.samples,
                    c.sigma,
                    c.chi2_twin,
                    c.chi2,
                    c.ei_factor,
                    c.curvature_factor,
                    c.damping_factor
                )
            })
        });
        match line {
            Ok(l) => println!("{l}"),
            Err(e) => {
                eprintln!("{} {} seed {seed}: {e}", effect.as_str(), kind.as_str());
                failed = true;
            }
        }
    }
    if failed {
        std::process::exit(1);
    }
}

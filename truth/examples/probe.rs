use trackbelt_truth::drop::{Contact, DropConfig};
use trackbelt_truth::law::*;
fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let n = args.first().copied().unwrap_or(36.0) as usize;
    let c = args.get(1).copied().unwrap_or(BendingLaw::SHREDDER_DAMPING);
    let f = args.get(2).copied().unwrap_or(1.0);
    let c = c * f;
    let mat = Material {
        elastic: BendingLaw::shredder().scaled(f, 1.0),
        damping: DampingLaw::Linear { c },
        friction: FrictionLaw::None,
        payne: None,
        thermal: None,
    };
    let cfg = DropConfig {
        length_m: 2.45,
        thickness_m: 0.008,
        mass_kg: 6.4,
        nodes: n,
        ea_n: 5e4,
        material: mat,
        ei_scale: vec![1.0; n],
        floor: Contact::floor(),
    };
    let t0 = std::time::Instant::now();
    let s = cfg.settle(0).unwrap();
    let t1 = t0.elapsed();
    let run = cfg.drop(&s, 1.3, 0.05, 6.0, 0.001).unwrap();
    println!(
        "N {n} h {:.2e} settle {:?} total {:?}",
        s.step_s,
        t1,
        t0.elapsed()
    );
    println!(
        "Hs {:.1} Ws {:.1} Hd {:.1} Wd {:.1} T/L {:?}",
        s.hs_m * 1e3,
        s.ws_m * 1e3,
        run.hd_m * 1e3,
        run.wd_m * 1e3,
        run.period_and_decrement()
    );
    let m = run.a_height_m.iter().cloned().fold(1e9, f64::min);
    println!("min A {:.1}", m * 1e3);
}

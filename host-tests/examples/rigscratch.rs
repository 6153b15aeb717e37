use trackbelt::params::{Method, Model, Variant};
use trackbelt::rig::{rig_test, Rig, RigConfig, RigTest};
use trackbelt::{ReferenceChain, Settings};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let method = Method::parse(&args[1]).unwrap();
    let speed: f64 = args[2].parse().unwrap();
    let step_ms: f64 = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(2.0);
    let model = Model::<f64>::paper(Variant::E56, method).unwrap();
    let mut s = Settings::default();
    s.step_s = step_ms * 1e-3;
    let t0 = std::time::Instant::now();
    let mut rig: Rig<f64, 132> = Rig::new(model, RigConfig::default(), s).unwrap();
    let _ = ReferenceChain::new;
    eprintln!(
        "settled in {:?}, d = {}",
        t0.elapsed(),
        rig.idler_position_m()
    );
    let test = RigTest {
        speed_rad_s: speed,
        ..Default::default()
    };
    let mut n = 0;
    let f = rig_test(&mut rig, &test, |s| {
        n += 1;
        if n % 100 == 0 {
            eprintln!("{:.3} {:.3} {:.4}", s.time_s, s.speed_rad_s, s.torque_nm);
        }
    })
    .unwrap();
    println!(
        "{:?} wall {:?} stats {:?}",
        f,
        t0.elapsed(),
        rig.chain().stats()
    );
}

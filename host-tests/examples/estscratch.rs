use trackbelt::estimator::{BuildOptions, Estimator, EstimatorTable};
use trackbelt::params::{Method, Model, Variant};
use trackbelt::rig::{rig_test, Rig, RigConfig, RigTest};
use trackbelt::Settings;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let method = Method::parse(&args[1]).unwrap();
    let phases: usize = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(8);
    let model = Model::<f64>::paper(Variant::E56, method).unwrap();
    let t0 = std::time::Instant::now();
    let opts = BuildOptions {
        phases,
        march_links: std::env::var("ML").map(|s| s.parse().unwrap()).unwrap_or(4),
        ..Default::default()
    };
    let rc = RigConfig {
        idler_damping_n_s_per_m: std::env::var("IC")
            .map(|s| s.parse().unwrap())
            .unwrap_or(2000.0),
        ..RigConfig::default()
    };
    let table = EstimatorTable::from_model::<64>(&model, &rc, &opts).unwrap();
    eprintln!(
        "built in {:?}: loss {:?} J {}",
        t0.elapsed(),
        table.loss_nm,
        table.inertia_kg_m2
    );
    let mut est = Estimator::new(table);
    for w in [1.0, 2.0, 5.0, 10.0] {
        let mut rig: Rig<f64, 64> =
            Rig::new(model.clone(), RigConfig::default(), Settings::default()).unwrap();
        let f = rig_test(
            &mut rig,
            &RigTest {
                speed_rad_s: w,
                ..Default::default()
            },
            |_| {},
        )
        .unwrap();
        est.reset();
        let e = est.update(w, 1e-3);
        println!(
            "w {w}: ref {:.4} (std {:.3}) est {:.4} err {:.2}%",
            f.torque_nm_mean,
            f.torque_nm_std,
            e.torque_nm,
            100.0 * (e.torque_nm / f.torque_nm_mean - 1.0)
        );
    }
}

use trackbelt_truth::law::*;
use trackbelt_truth::scroll::*;
struct P(f64);
impl Profile for P {
    fn omega(&self, t: f64) -> f64 {
        self.0 * (t / 1.0).min(1.0)
    }
    fn temp_rise(&self, _t: f64) -> f64 {
        0.0
    }
}
fn main() {
    let a: Vec<f64> = std::env::args()
        .skip(1)
        .map(|x| x.parse().unwrap())
        .collect();
    let n = a[0] as usize;
    let w = a[1];
    let mat = Material {
        elastic: BendingLaw::shredder(),
        damping: DampingLaw::Linear {
            c: BendingLaw::SHREDDER_DAMPING,
        },
        friction: FrictionLaw::None,
        payne: None,
        thermal: None,
    };
    let cfg = RigConfig {
        length_m: 2.45,
        thickness_m: 0.008,
        mass_kg: 6.4,
        nodes: n,
        ea_n: 2e5,
        material: mat,
        ei_scale: vec![1.0; n],
        drive_d_m: 0.3,
        idler_d_m: 0.3,
        idler_force_n: 500.0,
        bearing: None,
        idler_runout_m: 0.0,
        mu: 0.8,
        slip_windows: vec![],
        mu_slip: 0.8,
    };
    let t0 = std::time::Instant::now();
    let r = cfg.run(&P(w), 4.0, 0.001).unwrap();
    let k0 = r.t_s.iter().position(|&t| t > 2.0).unwrap();
    let tq = &r.torque_nm[k0..];
    let mean = tq.iter().sum::<f64>() / tq.len() as f64;
    let sd = (tq.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / tq.len() as f64).sqrt();
    // 100 ms averages
    let avg: Vec<String> = tq
        .chunks(100)
        .map(|c| format!("{:.2}", c.iter().sum::<f64>() / c.len() as f64))
        .collect();
    println!(
        "N {n} w {w} h {:.1e} wall {:.2}s mean {mean:.3} sd {sd:.3} C {:.4} 100ms-avgs {:?}",
        r.step_s,
        t0.elapsed().as_secs_f64(),
        r.center_distance_m,
        avg
    );
    if a.len() > 2 {
        for i in (0..400).step_by(5) {
            print!("{:.2} ", tq[i]);
        }
        println!();
    }
}

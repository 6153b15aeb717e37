use trackbelt::params::{Method, Model, Variant};
use trackbelt::rig::{rig_test, Rig, RigConfig, RigTest};
use trackbelt::Settings;
fn main() {
    let model = Model::<f64>::paper(Variant::E56, Method::I).unwrap();
    for (hold, settle, idler_c, wheel_c, slip) in [
        (2.0, 0.5, 2000.0, 200.0, 0.05),
        (2.0, 0.5, 2000.0, 200.0, 0.0005),
    ] {
        let cfg = RigConfig {
            idler_damping_n_s_per_m: idler_c,
            wheel_damping_n_s_per_m: wheel_c,
            slip_speed_m_s: slip,
            ..RigConfig::default()
        };
        let mut rig: Rig<f64, 64> = Rig::new(model.clone(), cfg, Settings::default()).unwrap();
        let f = rig_test(
            &mut rig,
            &RigTest {
                speed_rad_s: 1.0,
                hold_s: hold,
                settle_s: settle,
                ..Default::default()
            },
            |_| {},
        )
        .unwrap();
        println!(
            "hold {hold} settle {settle} idler_c {idler_c} wheel_c {wheel_c}: {:.4} std {:.4}",
            f.torque_nm_mean, f.torque_nm_std
        );
    }
}

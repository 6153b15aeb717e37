//! Issue 12, host side: a belt that is not the paper's (from the
//! independent truth generator), calibrated from its dataset, written as a
//! version 2 params file and simulated again from that file; and the
//! running gear a params file may carry.

use std::path::{Path, PathBuf};
use trackbelt::gear::{Ground, RunningGear, Tensioner, Wheel, WheelRole};
use trackbelt::rig::RigConfig;
use trackbelt_host::calibrate::{self, Options, Setup, Targets, DEFAULT_START};
use trackbelt_host::params_file::{parse_system, to_file};
use trackbelt_host::select::{select, Choice};
use trackbelt_host::sim::{simulate, Tests};
use trackbelt_host::Error;

/// Truth seed of a dynamic dataset of a belt that is not the paper's:
/// 1546 mm, 2.96 kg, 5.3 mm thick (its roller 0.59 kg).
const SEED: u64 = 78;

struct TempDir(PathBuf);

impl TempDir {
    fn new(tag: &str) -> TempDir {
        let p = std::env::temp_dir().join(format!("trackbelt-params-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).unwrap();
        TempDir(p)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn truth_dataset(dir: &Path) -> trackbelt_host::dataset::Dataset {
    use trackbelt_truth::{draw, generate, Outcome, SeriesKind};
    let sc = draw(Outcome::None, SeriesKind::Dynamic, SEED).unwrap();
    let ds = dir.join("belt");
    generate(&sc, &ds).unwrap();
    trackbelt_host::dataset::load(&ds).unwrap()
}

fn opts() -> Options {
    Options {
        threads: 2,
        per_run: false,
        ..Options::default()
    }
}

#[test]
fn a_non_paper_belt_calibrates_and_simulates_from_its_params_file() {
    let tmp = TempDir::new("cal");
    let ds = truth_dataset(&tmp.0);
    let b = ds.belt.belt(38);
    assert!((1.0..=1.8).contains(&b.length_m) && (1.5..=4.0).contains(&b.mass_kg));
    assert!(!calibrate::is_shredder(&b));
    let targets = Targets::of(&ds).unwrap();
    let setup = Setup::of_links(&ds, 38);
    let (start, note) = calibrate::start_for(&setup, &targets.mean).unwrap();
    assert!(note.is_some());
    let cal =
        calibrate::calibrate_links(&ds, 38, start, &opts(), &trackbelt_host::NoProgress).unwrap();
    // From the Shredder table as it is (the path), for comparison:
    // one fit, as before the Z1 restarts (session 50), and with them.
    let single = Options {
        z1_restarts: false,
        ..opts()
    };
    let old =
        calibrate::calibrate_links(&ds, 38, DEFAULT_START, &single, &trackbelt_host::NoProgress)
            .unwrap();
    let restarted =
        calibrate::calibrate_links(&ds, 38, DEFAULT_START, &opts(), &trackbelt_host::NoProgress)
            .unwrap();
    eprintln!(
        "belt {:.0} mm {:.2} kg: max error {:.2} % from the belt's start ({} simulations), \
         {:.2} % from the Shredder table in one fit, {:.2} % with {} restarts ({} simulations)",
        b.length_m * 1e3,
        b.mass_kg,
        cal.max_abs_rel_err_pct,
        cal.simulations,
        old.max_abs_rel_err_pct,
        restarted.max_abs_rel_err_pct,
        restarted.z1_restarts,
        restarted.simulations
    );
    // Method III's target (measured: 0.8 % against 16 % from the Shredder
    // table in one fit; the restarts take the Shredder start to 0.4 %).
    assert!(cal.max_abs_rel_err_pct <= 2.0, "{:?}", cal.rel_err_pct);
    assert!(cal.max_abs_rel_err_pct < old.max_abs_rel_err_pct);
    assert!(
        restarted.max_abs_rel_err_pct <= 2.0,
        "{:?}",
        restarted.rel_err_pct
    );

    // The params file it writes holds the dataset's belt …
    let text = calibrate::params_toml(&cal, "test").unwrap();
    let path = tmp.0.join("belt.toml");
    std::fs::write(&path, &text).unwrap();
    let sys = parse_system(&text, &path).unwrap();
    assert_eq!(sys.version, 2);
    assert!(sys.belt_given && sys.warnings.is_empty());
    assert_eq!(sys.belt.links, 38);
    assert!((sys.belt.length_m - b.length_m).abs() < 1e-12);
    assert!((sys.belt.mass_kg - b.mass_kg).abs() < 1e-12);
    // … and simulating from it (as `simulate --params`) reproduces the
    // calibrated figures (with the dataset's roller).
    let sel = select(&Choice {
        params: Some(&path),
        ..Choice::default()
    })
    .unwrap();
    assert_eq!(sel.model.belt.links, 38);
    let dynamic = trackbelt::bench::DynamicTest {
        roller_kg: setup.roller_kg,
        ..Default::default()
    };
    let (out, _) = simulate(
        sel.model,
        sel.method,
        Tests::Both,
        trackbelt::Settings::default(),
        dynamic,
    )
    .unwrap();
    let f = cal.fitted;
    let close = |a: f64, b: Option<f64>| (a - b.unwrap()).abs() <= 1e-6 * a.abs();
    assert!(close(out.hs_mm, f.hs_mm) && close(out.ws_mm, f.ws_mm));
    assert!(close(out.hd_mm.unwrap(), f.hd_mm) && close(out.wd_mm.unwrap(), f.wd_mm));
    assert!(close(out.period_s.unwrap(), f.period_s));
    assert!(close(out.log_decrement.unwrap(), f.log_decrement));
}

#[test]
fn the_paper_belt_keeps_the_built_in_start() {
    let ds = trackbelt_host::dataset::load(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../data/shredder-table1"),
    )
    .unwrap();
    let setup = Setup::of_links(&ds, 38);
    let targets = Targets::of(&ds).unwrap();
    let (start, note) = calibrate::start_for(&setup, &targets.mean).unwrap();
    assert_eq!(start, DEFAULT_START);
    assert!(note.is_none());
}

fn four_wheels() -> RunningGear<f64> {
    let mut g = RunningGear::new(Tensioner::Force { force_n: 400.0 });
    for (role, x, y, d) in [
        (WheelRole::Drive, 0.0, 0.0, 0.16),
        (WheelRole::Idler, 0.52, 0.0, 0.14),
        (WheelRole::Road, 0.17, -0.06, 0.09),
        (WheelRole::Road, 0.35, -0.06, 0.09),
    ] {
        g.push(Wheel {
            role,
            x_m: x,
            y_m: y,
            diameter_m: d,
        })
        .unwrap();
    }
    g.ground = Some(Ground { load_kg: 12.0 });
    g
}

#[test]
fn rig_takes_a_two_wheel_gear_and_refuses_others() {
    let tmp = TempDir::new("gear");
    let belt = trackbelt::params::Belt {
        length_m: 1.5,
        width_m: 0.12,
        thickness_m: 0.006,
        mass_kg: 2.5,
        links: 44,
    };
    let law = trackbelt::params::paper::joint_law(
        trackbelt::params::Variant::E38,
        trackbelt::params::Method::I,
    )
    .unwrap();
    // Two wheels of other diameters: the rig.
    let cfg = RigConfig {
        drive_diameter_m: 0.2,
        idler_diameter_m: 0.16,
        idler_force_n: 350.0,
        ..RigConfig::default()
    };
    let two = RunningGear::paper_rig(&cfg, 0.55).unwrap();
    let path = tmp.0.join("two.toml");
    std::fs::write(&path, toml_text(&belt, &law, &two)).unwrap();
    let sel = select(&Choice {
        params: Some(&path),
        ..Choice::default()
    })
    .unwrap();
    assert_eq!(sel.label, "N44");
    assert_eq!(sel.rig_config(None).unwrap(), cfg);
    assert_eq!(sel.rig_config(Some(200.0)).unwrap().idler_force_n, 200.0);
    // Four wheels on the ground: the running-gear simulation's job.
    let path = tmp.0.join("four.toml");
    std::fs::write(&path, toml_text(&belt, &law, &four_wheels())).unwrap();
    let sel = select(&Choice {
        params: Some(&path),
        ..Choice::default()
    })
    .unwrap();
    match sel.rig_config(None) {
        Err(Error::NeedsGearSimulation { wheels: 4, .. }) => {}
        other => panic!("{other:?}"),
    }
}

fn toml_text(
    belt: &trackbelt::params::Belt<f64>,
    law: &trackbelt::joint::JointLaw<f64>,
    gear: &RunningGear<f64>,
) -> String {
    to_file(None, Some(belt), law, Some(gear))
        .to_toml()
        .unwrap()
}

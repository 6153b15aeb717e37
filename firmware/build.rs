//! Build script: links with the repository's `memory.x`, and generates the
//! estimator's parameters from a params TOML file so that a calibration
//! (`trackbelt calibrate … --out FILE.toml`) reaches the firmware without
//! copying numbers by hand.
//!
//! The params file is `$TRACKBELT_PARAMS` if set (relative paths are taken
//! from `firmware/`), else the repository's `params/E56.toml`, else the
//! paper's method II law for E56 shipped in `firmware/params/`. It runs the
//! library's table builder (the chain's travelling-belt statics) on the
//! host and writes `$OUT_DIR/params.rs` with
//!
//! * `TABLE_F32`, `TABLE_FX`: the table in `f32` and 32.32 fixed point, as
//!   `static`s (read-only data in flash) with exact bit patterns, and their
//!   fingerprints;
//! * `CHECKPOINTS`: the full-precision (f64) estimator's torque every
//!   100 samples of the drive profile, which the firmware checks itself
//!   against;
//! * `VARIANT`, `METHOD`, `PARAMS_FILE`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::{env, fs, process};

use trackbelt::estimator::Estimator;

#[path = "src/profile.rs"]
#[allow(dead_code)]
mod profile;

/// Samples between checkpoints.
const CHECK_EVERY: u32 = 100;

fn fail(msg: String) -> ! {
    eprintln!("error: {msg}");
    process::exit(1);
}

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest =
        PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));

    // Memory layout: the repository root's memory.x.
    let memory_x = manifest.join("../memory.x");
    if let Err(e) = fs::copy(&memory_x, out.join("memory.x")) {
        fail(format!("cannot copy {}: {e}", memory_x.display()));
    }
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory_x.display());
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=src/profile.rs");
    println!("cargo:rerun-if-env-changed=TRACKBELT_PARAMS");

    let params = params_path(&manifest);
    println!("cargo:rerun-if-changed={}", params.display());
    let shown = params
        .strip_prefix(manifest.parent().unwrap_or(&manifest))
        .map(Path::to_path_buf)
        .unwrap_or_else(|_| params.clone());

    let ft =
        trackbelt_host::firmware::estimator_table(&params).unwrap_or_else(|e| fail(e.to_string()));

    let mut src = String::new();
    let _ = writeln!(
        src,
        "/// Variant of the params file (`N44` for a belt of 44 links that is no variant).\npub const VARIANT: &str = {:?};\n\
         /// Method of the params file.\npub const METHOD: &str = {:?};\n\
         /// The params file, relative to the repository root.\npub const PARAMS_FILE: &str = {:?};",
        ft.name(),
        ft.method.name(),
        shown.display().to_string(),
    );
    src.push_str(&trackbelt_host::firmware::table_consts(&ft.table));

    // The reference run: the f64 estimator over the same samples.
    let mut est = Estimator::new(&ft.table);
    let mut checkpoints = String::new();
    let mut scale: f64 = 0.0;
    for k in 0..profile::SAMPLES {
        let e = est.update(profile::speed_rad_s(k), profile::dt_s());
        if !e.status.is_ok() || !e.torque_nm.is_finite() {
            fail(format!(
                "the f64 estimator flags sample {k} (status {:?}): is the profile inside the table's speed range?",
                e.status
            ));
        }
        scale = scale.max(e.torque_nm.abs());
        if k % CHECK_EVERY == 0 || k + 1 == profile::SAMPLES {
            let _ = writeln!(
                checkpoints,
                "    Checkpoint {{ k: {k}, torque_nm: {:e} }},",
                e.torque_nm
            );
        }
    }
    let _ = writeln!(
        src,
        "/// The f64 estimator's torque along the drive profile.\n\
         pub const CHECKPOINTS: &[Checkpoint] = &[\n{checkpoints}];\n\
         /// Largest |torque| of the f64 run, N·m.\npub const TORQUE_SCALE_NM: f32 = {:e};",
        scale as f32
    );
    if let Err(e) = fs::write(out.join("params.rs"), src) {
        fail(format!("cannot write params.rs: {e}"));
    }
    if env::var_os("CARGO_FEATURE_GEAR").is_some() {
        gear_params(&manifest, &out);
    }
}

/// The running-gear example's parameters (feature `gear`):
/// `$OUT_DIR/gear_params.rs` with `GEAR_TABLE_F32` (speed × belt
/// temperature), its fingerprint, and the f64 reference run's checkpoints
/// along the drive and temperature profiles. The params file is
/// `$TRACKBELT_GEAR_PARAMS` if set (relative to `firmware/`), else
/// `firmware/params/gear-4wheel.toml`.
fn gear_params(manifest: &Path, out: &Path) {
    println!("cargo:rerun-if-env-changed=TRACKBELT_GEAR_PARAMS");
    let params = match env::var_os("TRACKBELT_GEAR_PARAMS") {
        Some(p) => {
            let p = PathBuf::from(p);
            if p.is_relative() {
                manifest.join(p)
            } else {
                p
            }
        }
        None => manifest.join("params/gear-4wheel.toml"),
    };
    if !params.is_file() {
        fail(format!("{}: no such params file", params.display()));
    }
    println!("cargo:rerun-if-changed={}", params.display());
    let shown = params
        .strip_prefix(manifest.parent().unwrap_or(manifest))
        .map(Path::to_path_buf)
        .unwrap_or_else(|_| params.clone());
    let gt = trackbelt_host::firmware::gear_estimator_table(&params)
        .unwrap_or_else(|e| fail(e.to_string()));
    for w in &gt.system.warnings {
        println!("cargo:warning={w}");
    }
    let mut src = String::new();
    let _ = writeln!(
        src,
        "/// The params file, relative to the repository root.\npub const GEAR_PARAMS_FILE: &str = {:?};\n\
         /// Links of the belt.\npub const GEAR_LINKS: u32 = {};\n\
         /// Wheels of the running gear.\npub const GEAR_WHEELS: u32 = {};\n\
         /// The belt's name in the log: a variant's (`E56`) or `N` and the links.\npub const GEAR_BELT: &str = {:?};\n\
         /// The joint law's method (`I`, `II`, `III`).\npub const GEAR_METHOD: &str = {:?};",
        shown.display().to_string(),
        gt.system.belt.links,
        gt.system.gear.as_ref().map_or(0, |g| g.wheels.len()),
        trackbelt::params::Variant::ALL
            .into_iter()
            .find(|v| v.links() == gt.system.belt.links)
            .map_or_else(|| format!("N{}", gt.system.belt.links), |v| v.name().to_string()),
        gt.system.method.name(),
    );
    src.push_str(&trackbelt_host::firmware::gear_table_consts(&gt.table));
    let mut state = trackbelt::estimator::EstimatorState::new();
    let mut checkpoints = String::new();
    let mut scale: f64 = 0.0;
    for k in 0..profile::SAMPLES {
        let e = gt.table.update(
            &mut state,
            profile::speed_rad_s(k),
            profile::dt_s(),
            Some(profile::temperature_c(k)),
            None,
        );
        if !e.status.is_ok() || !e.torque_nm.is_finite() {
            fail(format!(
                "the f64 running-gear estimator flags sample {k} (status {:?})",
                e.status
            ));
        }
        scale = scale.max(e.torque_nm.abs());
        if k % CHECK_EVERY == 0 || k + 1 == profile::SAMPLES {
            let _ = writeln!(
                checkpoints,
                "    Checkpoint {{ k: {k}, torque_nm: {:e} }},",
                e.torque_nm
            );
        }
    }
    let _ = writeln!(
        src,
        "/// The f64 running-gear estimator's torque along the profiles.\n\
         pub const GEAR_CHECKPOINTS: &[Checkpoint] = &[\n{checkpoints}];\n\
         /// Largest |torque| of the f64 run, N·m.\npub const GEAR_TORQUE_SCALE_NM: f32 = {:e};",
        scale as f32
    );
    if let Err(e) = fs::write(out.join("gear_params.rs"), src) {
        fail(format!("cannot write gear_params.rs: {e}"));
    }
}

fn params_path(manifest: &Path) -> PathBuf {
    if let Some(p) = env::var_os("TRACKBELT_PARAMS") {
        let p = PathBuf::from(p);
        let p = if p.is_relative() { manifest.join(p) } else { p };
        if !p.is_file() {
            fail(format!("TRACKBELT_PARAMS={}: no such file", p.display()));
        }
        return p;
    }
    // Watch the repository's params/ (when it exists) for a calibration
    // appearing or changing.
    let dir = manifest.parent().unwrap_or(manifest).join("params");
    if dir.is_dir() {
        println!("cargo:rerun-if-changed={}", dir.display());
    }
    let shipped = dir.join("E56.toml");
    if shipped.is_file() {
        return shipped;
    }
    println!(
        "cargo:warning=no params/E56.toml in the repository: using the paper's method II law (firmware/params/E56-method-II.toml)"
    );
    manifest.join("params/E56-method-II.toml")
}

//! The firmware on QEMU against the same estimator build on the host.
//!
//! Builds `firmware/` for both boards, runs each under QEMU through the
//! firmware's own runner (`firmware/qemu-run.sh`, `-icount shift=0`), and
//! replays the run on the host: the same params file (read from the
//! firmware's log), the same table (its fingerprint must match), the same
//! drive samples (`firmware/src/profile.rs`, included below). The logged
//! torques must be bit-identical in fixed point (lm3s6965evb) and within
//! 1e-5 relative in f32 (mps2-an386). The firmware must also pass its own
//! checks and exit 0.
//!
//! Skipped, with a message, only where `qemu-system-arm` is not installed
//! (CI installs it); a missing `defmt-print` or Cortex-M target is a
//! failure that says what to install.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use trackbelt::estimator::{Estimator, EstimatorTable};
use trackbelt::estimator::{EstimatorState, GearTable};
use trackbelt::{Fx, Real};
use trackbelt_host::firmware::{
    estimator_table, f32_bits, fx_bits, gear_estimator_table, gear_table_hash, table_hash,
};

#[path = "../../firmware/src/profile.rs"]
mod profile;

/// A line on the test's stderr that `cargo test` shows even for a passing
/// test (libtest captures `eprintln!`, not the stream itself).
fn say(msg: &str) {
    use std::io::Write as _;
    let _ = writeln!(std::io::stderr(), "{msg}");
}

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn have(tool: &str) -> bool {
    Command::new(tool)
        .arg("--version")
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

/// `cargo build --release` of one board inside `firmware/` (its own
/// workspace), with the outer cargo's build settings removed.
fn build_firmware(bin: &str, target: &str) -> PathBuf {
    build_firmware_with(bin, target, &[])
}

/// [`build_firmware`] with extra cargo arguments (`--features gear`).
fn build_firmware_with(bin: &str, target: &str, extra: &[&str]) -> PathBuf {
    let fw = repo_root().join("firmware");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(&fw)
        .args(["build", "--release", "--bin", bin, "--target", target])
        .args(extra);
    for var in [
        "CARGO_TARGET_DIR",
        "CARGO_BUILD_TARGET",
        "CARGO_BUILD_TARGET_DIR",
        "RUSTFLAGS",
        "CARGO_ENCODED_RUSTFLAGS",
        "CARGO_BUILD_RUSTFLAGS",
        "RUSTC_WRAPPER",
        "RUSTC_WORKSPACE_WRAPPER",
        "CARGO_MANIFEST_DIR",
        "CARGO_PRIMARY_PACKAGE",
    ] {
        cmd.env_remove(var);
    }
    let out = cmd.output().expect("run cargo for the firmware");
    assert!(
        out.status.success(),
        "building the firmware ({bin}, {target}) failed (is the target installed? \
         `rustup target add {target}`):\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    fw.join("target").join(target).join("release").join(bin)
}

fn run_on_qemu(elf: &Path) -> Output {
    let runner = repo_root().join("firmware/qemu-run.sh");
    Command::new("bash")
        .arg(&runner)
        .arg(elf)
        .args(["--log-format", "{s}"])
        .output()
        .expect("run firmware/qemu-run.sh")
}

/// `key=value` from a log line (value up to the next space).
fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(key)?.strip_prefix('='))
}

fn hex(s: &str) -> u64 {
    u64::from_str_radix(s.trim_start_matches("0x"), 16).unwrap_or_else(|e| panic!("{s}: {e}"))
}

/// One logged telemetry line: sample index and torque bits.
struct Logged {
    k: u32,
    bits: u64,
}

struct Run {
    params_file: PathBuf,
    table_hash: u64,
    instructions_per_update: u32,
    ram_bytes: u32,
    records: Vec<Logged>,
}

fn parse(stdout: &str) -> Run {
    let mut params_file = None;
    let mut table_hash_v = None;
    let mut cost = None;
    let mut records = Vec::new();
    for line in stdout.lines() {
        if let (Some(p), Some(h)) = (field(line, "params_file"), field(line, "table_hash")) {
            params_file = Some(repo_root().join(p));
            table_hash_v = Some(hex(h));
        }
        if let (Some(i), Some(r)) = (
            field(line, "instructions_per_update"),
            field(line, "ram_bytes"),
        ) {
            cost = Some((i.parse().unwrap(), r.parse().unwrap()));
        }
        if let (Some(t), Some(b)) = (field(line, "t"), field(line, "bits")) {
            records.push(Logged {
                k: t.parse().unwrap(),
                bits: hex(b),
            });
        }
    }
    let (instructions_per_update, ram_bytes) =
        cost.unwrap_or_else(|| panic!("no cost line in the log:\n{stdout}"));
    Run {
        params_file: params_file.unwrap_or_else(|| panic!("no params_file in the log:\n{stdout}")),
        table_hash: table_hash_v.unwrap(),
        instructions_per_update,
        ram_bytes,
        records,
    }
}

/// The host's run of the same estimator build over the drive profile:
/// torque at every sample.
fn replay<T: Real>(table: EstimatorTable<T>) -> Vec<T> {
    let mut est = Estimator::new(&table);
    let dt = T::from_f64(profile::dt_s());
    (0..profile::SAMPLES)
        .map(|k| {
            est.update(T::from_f64(profile::speed_rad_s(k)), dt)
                .torque_nm
        })
        .collect()
}

fn board_run(bin: &str, target: &str) -> Option<(Run, EstimatorTable<f64>)> {
    if !have("qemu-system-arm") {
        say(&format!(
            "SKIPPED {bin}: qemu-system-arm is not installed, so the firmware cannot run here \
             (apt-get install qemu-system-arm; CI installs it)"
        ));
        return None;
    }
    assert!(
        have("defmt-print"),
        "defmt-print is needed to decode the firmware's log: cargo install defmt-print --locked"
    );
    let elf = build_firmware(bin, target);
    let out = run_on_qemu(&elf);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && stdout.lines().any(|l| l.trim() == "PASS"),
        "{bin} on QEMU failed ({}):\n{stdout}\n{stderr}",
        out.status
    );
    let run = parse(&stdout);
    let ft = estimator_table(&run.params_file).unwrap();
    Some((run, ft.table))
}

fn check_records(run: &Run) {
    // Every TELEMETRY_EVERY-th sample and the last one.
    let expected = (profile::SAMPLES - 1) / 50 + 2;
    assert_eq!(run.records.len() as u32, expected, "telemetry lines");
    assert!(run.instructions_per_update > 0 && run.ram_bytes > 0);
}

#[test]
fn fixed_point_firmware_matches_the_host_bit_for_bit() {
    let Some((run, table)) = board_run("lm3s6965evb", "thumbv7m-none-eabi") else {
        return;
    };
    check_records(&run);
    let tfx: EstimatorTable<Fx> = table.cast();
    assert_eq!(
        run.table_hash,
        table_hash(&tfx, fx_bits),
        "the firmware's table is not the one the host builds from {}",
        run.params_file.display()
    );
    let host = replay(tfx);
    for r in &run.records {
        let h = host[r.k as usize];
        assert_eq!(
            r.bits,
            h.to_bits() as u64,
            "sample {}: firmware {:#x}, host {:#x} ({h:?} N·m)",
            r.k,
            r.bits,
            h.to_bits()
        );
    }
    say(&format!(
        "lm3s6965evb: {} logged torques bit-identical to the host's I32F32 run; \
         instructions_per_update={} ram_bytes={}",
        run.records.len(),
        run.instructions_per_update,
        run.ram_bytes
    ));
}

#[test]
fn f32_firmware_matches_the_host_within_1e_5() {
    let Some((run, table)) = board_run("mps2-an386", "thumbv7em-none-eabihf") else {
        return;
    };
    check_records(&run);
    let t32: EstimatorTable<f32> = table.cast();
    assert_eq!(
        run.table_hash,
        table_hash(&t32, f32_bits),
        "the firmware's table is not the one the host builds from {}",
        run.params_file.display()
    );
    let host = replay(t32);
    let mut identical = 0;
    for r in &run.records {
        let h = host[r.k as usize];
        let fw = f32::from_bits(r.bits as u32);
        let scale = h.abs().max(f32::MIN_POSITIVE);
        assert!(
            (fw - h).abs() <= 1e-5 * scale,
            "sample {}: firmware {fw} N·m, host {h} N·m",
            r.k
        );
        identical += usize::from(fw.to_bits() == h.to_bits());
    }
    say(&format!(
        "mps2-an386: {} logged torques within 1e-5 of the host's f32 run ({identical} bit-identical); \
         instructions_per_update={} ram_bytes={}",
        run.records.len(),
        run.instructions_per_update,
        run.ram_bytes
    ));
}

#[test]
fn drive_profile_ramps_holds_and_steps_within_its_slew_limit() {
    assert_eq!(profile::speed_mrad_s(0), 0);
    assert_eq!(profile::speed_mrad_s(500), 2_500);
    assert_eq!(profile::speed_mrad_s(1_000), 5_000);
    assert_eq!(profile::speed_mrad_s(1_500), 5_000);
    assert_eq!(profile::speed_mrad_s(1_700), 3_000);
    assert_eq!(profile::speed_mrad_s(profile::SAMPLES - 1), 5_000);
    let (mut lo, mut hi) = (0, 0);
    for k in 1..profile::SAMPLES {
        let (a, b) = (profile::speed_mrad_s(k - 1), profile::speed_mrad_s(k));
        assert!((b - a).abs() <= 25, "slew at {k}: {a} -> {b}");
        lo = lo.min(b);
        hi = hi.max(b);
    }
    assert_eq!((lo, hi), (0, 5_000));
    assert_eq!(profile::speed_rad_s(1_234), 5.0);
}

/// The second example (four-wheel running gear, belt temperature input,
/// feature `gear`) built and run on QEMU: the run and the table the host
/// builds from the params file it names (fingerprint checked).
fn gear_run(bin: &str, target: &str) -> Option<(Run, GearTable<f64>)> {
    if !have("qemu-system-arm") {
        say(&format!("SKIPPED {bin}: qemu-system-arm is not installed"));
        return None;
    }
    assert!(have("defmt-print"), "cargo install defmt-print --locked");
    let elf = build_firmware_with(bin, target, &["--features", "gear"]);
    let out = run_on_qemu(&elf);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && stdout.lines().any(|l| l.trim() == "PASS"),
        "{bin} on QEMU failed ({}):\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let run = parse(&stdout);
    check_records(&run);
    let gt = gear_estimator_table(&run.params_file).unwrap();
    Some((run, gt.table))
}

/// The host's run of a running-gear table over the drive and temperature
/// profiles, with the inputs converted as the firmware converts them.
fn gear_replay<T: Real>(table: &GearTable<T>, temperature: impl Fn(u32) -> T) -> Vec<T> {
    let mut state = EstimatorState::new();
    let dt = T::from_f64(profile::dt_s());
    (0..profile::SAMPLES)
        .map(|k| {
            table
                .update(
                    &mut state,
                    T::from_f64(profile::speed_rad_s(k)),
                    dt,
                    Some(temperature(k)),
                    None,
                )
                .torque_nm
        })
        .collect()
}

/// mps2-an386 (f32): within 1e-5 of the host's f32 run, and the budget
/// (≤ 400 instructions per update on the M4F, ≤ 4 KiB RAM, ≤ 8 KiB table).
#[test]
fn running_gear_firmware_matches_the_host_within_1e_5() {
    let Some((run, table)) = gear_run("gear-mps2-an386", "thumbv7em-none-eabihf") else {
        return;
    };
    let t32: GearTable<f32> = table.cast();
    assert_eq!(
        run.table_hash,
        gear_table_hash(&t32, f32_bits),
        "the firmware's table is not the one the host builds from {}",
        run.params_file.display()
    );
    let host = gear_replay(&t32, profile::temperature_c_f32);
    let mut identical = 0;
    for r in &run.records {
        let h = host[r.k as usize];
        let fw = f32::from_bits(r.bits as u32);
        assert!(
            (fw - h).abs() <= 1e-5 * h.abs().max(f32::MIN_POSITIVE),
            "sample {}: firmware {fw} N·m, host {h} N·m",
            r.k
        );
        identical += usize::from(fw.to_bits() == h.to_bits());
    }
    assert!(
        run.instructions_per_update <= 400,
        "{}",
        run.instructions_per_update
    );
    assert!(run.ram_bytes <= 4096);
    assert!(std::mem::size_of::<GearTable<f32>>() <= 8192);
    say(&format!(
        "gear-mps2-an386: {} logged torques within 1e-5 of the host's f32 run ({identical} bit-identical); \
         instructions_per_update={} ram_bytes={}",
        run.records.len(),
        run.instructions_per_update,
        run.ram_bytes
    ));
}

/// lm3s6965evb (32.32 fixed point): bit for bit.
#[test]
fn running_gear_fixed_point_firmware_matches_the_host_bit_for_bit() {
    let Some((run, table)) = gear_run("gear-lm3s6965evb", "thumbv7m-none-eabi") else {
        return;
    };
    let tfx: GearTable<Fx> = table.cast();
    assert_eq!(
        run.table_hash,
        gear_table_hash(&tfx, fx_bits),
        "the firmware's table is not the one the host builds from {}",
        run.params_file.display()
    );
    let host = gear_replay(&tfx, |k| Fx::from_f64(profile::temperature_c(k)));
    for r in &run.records {
        let h = host[r.k as usize];
        assert_eq!(
            r.bits,
            h.to_bits() as u64,
            "sample {}: firmware {:#x}, host {:#x} ({h:?} N·m)",
            r.k,
            r.bits,
            h.to_bits()
        );
    }
    assert!(std::mem::size_of::<GearTable<Fx>>() <= 8192);
    say(&format!(
        "gear-lm3s6965evb: {} logged torques bit-identical to the host's I32F32 run; \
         instructions_per_update={} ram_bytes={}",
        run.records.len(),
        run.instructions_per_update,
        run.ram_bytes
    ));
}

#[test]
fn temperature_profile_warms_from_20_to_50_c() {
    assert_eq!(profile::temperature_centi_c(0), 2_000);
    assert_eq!(profile::temperature_centi_c(profile::SAMPLES), 5_000);
    assert_eq!(profile::temperature_c(2_000), 35.0);
}

//! `trackbelt monitor` on synthetic scroll datasets (`trackbelt synth
//! --kind scroll`): the JSON contract (SPEC section 7), one and several
//! series, the bearing friction found, errors.

use std::path::{Path, PathBuf};
use std::process::Command;

fn trackbelt_bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_trackbelt"))
}

fn synth(name: &str, effect: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("trackbelt-monitor-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = trackbelt_bin()
        .args([
            "synth",
            "--kind",
            "scroll",
            "--variant",
            "E56",
            "--effect",
            effect,
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir
}

fn monitor_json(dir: &Path) -> serde_json::Value {
    let out = trackbelt_bin()
        .args(["monitor", "--json"])
        .arg(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object on stdout")
}

#[test]
fn monitor_json_contract_and_bearing_friction() {
    let clean = synth("clean", "none");
    let v = monitor_json(&clean);
    for key in [
        "loss_scale",
        "loss_scale_sd",
        "bearing_nm",
        "alarm",
        "alarm_at_s",
        "series",
    ] {
        assert!(v.get(key).is_some(), "missing {key}: {v}");
    }
    // The synthetic belt has 10 % more damping than the baseline.
    let s = v["loss_scale"].as_f64().unwrap();
    assert!((1.0..1.2).contains(&s), "{v}");
    assert_eq!(v["alarm"], false, "{v}");
    assert!(v["alarm_at_s"].is_null(), "{v}");
    assert_eq!(v["series"], "run-1");
    let b0 = v["bearing_nm"].as_f64().unwrap();

    // 0.5 N·m of bearing friction (the effect's nominal size).
    let bearing = synth("bearing", "bearing_friction");
    let w = monitor_json(&bearing);
    let db = w["bearing_nm"].as_f64().unwrap() - b0;
    assert!((db / 0.5 - 1.0).abs() <= 0.1, "{w}");
    let s2 = w["loss_scale"].as_f64().unwrap();
    assert!((s2 / s - 1.0).abs() <= 0.05, "{w}");

    // Two series: {"results": [...]}.
    let toml = std::fs::read_to_string(clean.join("dataset.toml")).unwrap();
    let entry = &toml[toml.find("[[scroll]]").unwrap()..];
    let two = format!("{toml}\n{}", entry.replace("run-1", "run-2"));
    std::fs::write(clean.join("dataset.toml"), two).unwrap();
    let r = monitor_json(&clean);
    let results = r["results"].as_array().expect("results");
    assert_eq!(results.len(), 2);
    assert_eq!(results[1]["series"], "run-2");
    assert_eq!(results[0]["loss_scale"], results[1]["loss_scale"]);

    // The readable report and the plot.
    let plots = clean.join("plots");
    let out = trackbelt_bin()
        .arg("monitor")
        .arg(&clean)
        .arg("--plot")
        .arg(&plots)
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("loss scale"));
    assert!(plots.join("monitor-1.svg").is_file());

    for dir in [clean, bearing] {
        let _ = std::fs::remove_dir_all(dir);
    }
}

#[test]
fn monitor_errors_exit_non_zero() {
    let out = trackbelt_bin()
        .args(["monitor", "/nonexistent/trackbelt-dataset", "--json"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let dir = synth("badvariant", "none");
    let out = trackbelt_bin()
        .args(["monitor", "--variant", "E99"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--variant"));
    let _ = std::fs::remove_dir_all(dir);
}

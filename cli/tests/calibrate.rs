//! `trackbelt calibrate`: the measured Table 1 dataset is fitted within the
//! 2 % target (E38, the full command with its JSON), and malformed datasets
//! give an error naming the file and line and write nothing.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn trackbelt_bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_trackbelt"))
}

fn table1() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../data/shredder-table1")
}

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("trackbelt-calib-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn calibrate(dataset: &Path, out: &Path, extra: &[&str]) -> Output {
    trackbelt_bin()
        .arg("calibrate")
        .arg(dataset)
        .args(["--variant", "E38", "--json", "--out"])
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

const MANIFEST: &str = r#"format = 1
name = "tiny"

[belt]
length_mm = 2450
width_mm = 160
thickness_mm = 8
mass_kg = 6.4

[[static]]
label = "a"
hs_mm = 329
ws_mm = 1068

[[dynamic]]
label = "a"
roller_kg = 1.3
hd_mm = 231
wd_mm = 1087
period_s = 0.75
log_decrement = 0.76
series = "dyn.csv"
"#;

fn csv(bad_rows: usize) -> String {
    let mut s = String::from("t_s,a_height_mm\n");
    for i in 0..40 {
        if i >= 5 && i < 5 + bad_rows {
            s.push_str(&format!("{:.2},oops\n", i as f64 * 0.04));
        } else {
            s.push_str(&format!("{:.2},{}\n", i as f64 * 0.04, 300 - i));
        }
    }
    s
}

/// Write a dataset, run calibrate on it, and check it fails naming
/// `file:line` (or `file` and `line N`) and writes nothing.
fn assert_rejected(name: &str, manifest: &str, csv_text: &str, expect: &[&str]) {
    let dir = scratch(name);
    let ds = dir.join("ds");
    std::fs::create_dir_all(&ds).unwrap();
    std::fs::write(ds.join("dataset.toml"), manifest).unwrap();
    std::fs::write(ds.join("dyn.csv"), csv_text).unwrap();
    let out_file = dir.join("out.toml");
    let out = calibrate(&ds, &out_file, &[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{name}: should fail");
    assert!(out.stdout.is_empty(), "{name}: stdout not empty");
    for e in expect {
        assert!(stderr.contains(e), "{name}: {e:?} not in {stderr}");
    }
    assert!(!out_file.exists(), "{name}: wrote {}", out_file.display());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn malformed_datasets_name_file_and_line_and_write_nothing() {
    let good = csv(0);
    // Missing required field.
    assert_rejected(
        "missing",
        &MANIFEST.replace("ws_mm = 1068\n", ""),
        &good,
        &["dataset.toml:10:", "ws_mm"],
    );
    // Wrong type.
    assert_rejected(
        "type",
        &MANIFEST.replace("hs_mm = 329", "hs_mm = \"329\""),
        &good,
        &["dataset.toml:12:", "hs_mm"],
    );
    // Bad CSV rows (more than 5 % of them).
    assert_rejected("csv", MANIFEST, &csv(4), &["dyn.csv", "line 7"]);
    // Unknown format version.
    assert_rejected(
        "format",
        &MANIFEST.replace("format = 1", "format = 7"),
        &good,
        &["dataset.toml:1:", "format"],
    );
    // Empty dataset.
    let empty = &MANIFEST[..MANIFEST.find("[[static]]").unwrap()];
    assert_rejected("empty", empty, &good, &["dataset.toml:8", "empty dataset"]);
}

#[test]
fn one_bad_csv_row_is_reported_with_file_and_line() {
    let dir = scratch("onebad");
    let ds = dir.join("ds");
    std::fs::create_dir_all(&ds).unwrap();
    std::fs::write(ds.join("dataset.toml"), MANIFEST).unwrap();
    std::fs::write(ds.join("dyn.csv"), csv(1)).unwrap();
    // A zero-iteration budget from the built-in start misses 2 %: the
    // command fails without writing, but the warning is printed first.
    let out_file = dir.join("out.toml");
    let out = calibrate(&ds, &out_file, &["--max-iterations", "0", "--no-spread"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("dyn.csv:7"), "{stderr}");
    assert!(!out.status.success());
    assert!(!out_file.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn refuses_to_write_into_the_dataset_directory() {
    let dir = scratch("inside");
    let ds = dir.join("ds");
    std::fs::create_dir_all(&ds).unwrap();
    std::fs::write(ds.join("dataset.toml"), MANIFEST).unwrap();
    std::fs::write(ds.join("dyn.csv"), csv(0)).unwrap();
    let out = calibrate(&ds, &ds.join("dataset.toml"), &["--max-iterations", "0"]);
    assert!(!out.status.success());
    assert_eq!(
        std::fs::read_to_string(ds.join("dataset.toml")).unwrap(),
        MANIFEST,
        "input overwritten"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn table1_dataset_is_fitted_within_2_percent_for_e38() {
    let dir = scratch("table1");
    let out_file = dir.join("x.toml");
    let out = calibrate(&table1(), &out_file, &[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(v["variant"], "E38");
    assert_eq!(v["within_2pct"], true);
    let e = &v["rel_err_pct"];
    for k in [
        "hs_mm",
        "ws_mm",
        "hd_mm",
        "wd_mm",
        "period_s",
        "log_decrement",
    ] {
        let x = e[k].as_f64().unwrap_or(f64::INFINITY);
        assert!(x.abs() <= 2.0, "{k}: {x} %");
        assert!(v["fitted"][k].is_number() && v["target"][k].is_number());
    }
    assert_eq!(v["angles_deg"].as_array().unwrap().len(), 6);
    assert!(v["cz_nmms_per_rad"].as_f64().unwrap() > 0.0);
    assert!(v["wall_s"].as_f64().unwrap() > 0.0);
    // The spread over the eight repeat runs.
    assert_eq!(v["spread"]["runs"].as_array().unwrap().len(), 8);
    assert!(v["spread"]["cz_nmms_per_rad"]["std"].as_f64().unwrap() > 0.0);
    assert!(v["spread"]["fitted"]["hd_mm"]["std"].as_f64().unwrap() > 0.0);
    // The params file simulates to the fitted figures.
    let text = std::fs::read_to_string(&out_file).unwrap();
    assert!(text.starts_with("# Method III"), "{text}");
    let sim = trackbelt_bin()
        .args([
            "simulate",
            "--variant",
            "E38",
            "--method",
            "III",
            "--json",
            "--params",
        ])
        .arg(&out_file)
        .output()
        .unwrap();
    assert!(sim.status.success());
    let s: serde_json::Value = serde_json::from_slice(&sim.stdout).unwrap();
    assert_eq!(s["hd_mm"], v["fitted"]["hd_mm"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_params_file_for_another_variant_is_refused() {
    let e38 = concat!(env!("CARGO_MANIFEST_DIR"), "/../params/E38.toml");
    let out = trackbelt_bin()
        .args([
            "simulate",
            "--variant",
            "E56",
            "--method",
            "III",
            "--json",
            "--params",
            e38,
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("made for E38"), "{stderr}");
    assert!(out.stdout.is_empty());
}

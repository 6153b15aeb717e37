//! The `trackbelt` binary: the JSON contract and error handling.

use std::process::Command;

fn trackbelt_bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_trackbelt"))
}

/// Runs `cmd`, asserts that it succeeded (showing its stderr otherwise)
/// and parses its stdout as one JSON object.
fn json_ok(cmd: &mut Command) -> serde_json::Value {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// A reader that closes the pipe early (`trackbelt diagnose DIR | head`)
/// ends the command by SIGPIPE, as for any Unix tool, not by a panic on
/// the closed pipe (which printed a backtrace before).
#[cfg(unix)]
#[test]
fn a_closed_stdout_ends_the_command_quietly() {
    use std::os::unix::process::ExitStatusExt;
    use std::process::Stdio;
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../data/synthetic-scroll-bearing"
    );
    let mut child = trackbelt_bin()
        .args(["diagnose", dir])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Close the read end before anything is printed.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.signal(), Some(libc::SIGPIPE), "{stderr}");
}

#[test]
fn cli_reports_bad_arguments_and_exits_non_zero() {
    let out = trackbelt_bin()
        .args(["simulate", "--variant", "E99", "--method", "I", "--json"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--variant"));
    let out = trackbelt_bin()
        .args(["simulate", "--variant", "E38", "--method", "IV", "--json"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--method"));
    let dir = std::env::temp_dir().join(format!("trackbelt-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("bad.toml");
    std::fs::write(
        &p,
        "method = \"I\"\n[stiffness]\nkz_nmm_per_rad = -5\n[damping]\ncz_nmms_per_rad = 450\n",
    )
    .unwrap();
    let out = trackbelt_bin()
        .args([
            "simulate",
            "--variant",
            "E38",
            "--method",
            "I",
            "--json",
            "--params",
        ])
        .arg(&p)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("kz"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stdout.is_empty());
}

#[test]
fn cli_simulate_json_has_the_contract_fields() {
    let v =
        json_ok(trackbelt_bin().args(["simulate", "--variant", "E38", "--method", "I", "--json"]));
    for k in [
        "variant",
        "method",
        "hs_mm",
        "ws_mm",
        "hd_mm",
        "wd_mm",
        "period_s",
        "log_decrement",
        "angle_a_deg",
        "angle_c_deg",
        "wall_s",
    ] {
        assert!(v.get(k).is_some(), "missing {k}");
    }
    assert_eq!(v["angle_a_deg"].as_array().unwrap().len(), 2);
    let out = trackbelt_bin()
        .args([
            "simulate",
            "--variant",
            "E38",
            "--method",
            "II",
            "--test",
            "static",
            "--json",
        ])
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["hd_mm"].is_null());
    assert!(v["hs_mm"].as_f64().unwrap() > 300.0);
}

fn simulate_json(extra: &[&str]) -> serde_json::Value {
    json_ok(
        trackbelt_bin()
            .args(["simulate", "--variant", "E38", "--method", "II", "--json"])
            .args(extra),
    )
}

#[test]
fn cli_simulate_with_the_literal_bushing_agrees_with_pins() {
    let pin = simulate_json(&[]);
    let bushing = simulate_json(&["--joint", "bushing"]);
    assert_eq!(pin["joint"], "pin");
    assert!(pin["max_stretch_um"].is_null());
    assert_eq!(bushing["joint"], "bushing");
    let stretch = bushing["max_stretch_um"].as_f64().unwrap();
    assert!(stretch > 0.0 && stretch < 50.0, "stretch {stretch} µm");
    for k in ["hs_mm", "ws_mm", "hd_mm", "wd_mm", "period_s"] {
        let (a, b) = (pin[k].as_f64().unwrap(), bushing[k].as_f64().unwrap());
        assert!((a - b).abs() < 0.01 * a.abs(), "{k}: pin {a}, bushing {b}");
    }
    let out = trackbelt_bin()
        .args([
            "simulate",
            "--variant",
            "E38",
            "--method",
            "II",
            "--joint",
            "spring",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--joint"));
}

#[test]
fn cli_simulate_method_three_uses_the_shipped_calibrated_table() {
    // Without --params, method III uses params/E38.toml (embedded): the
    // same figures as passing that file explicitly.
    let shipped = concat!(env!("CARGO_MANIFEST_DIR"), "/../params/E38.toml");
    let run = |extra: &[&str]| {
        json_ok(
            trackbelt_bin()
                .args(["simulate", "--variant", "E38", "--method", "III", "--json"])
                .args(extra),
        )
    };
    let a = run(&[]);
    let b = run(&["--params", shipped]);
    assert_eq!(a["method"], "III");
    for k in ["hs_mm", "hd_mm", "period_s", "log_decrement"] {
        assert_eq!(a[k], b[k], "{k}");
    }
    let hd = a["hd_mm"].as_f64().unwrap();
    assert!((hd - 225.0).abs() <= 0.02 * 225.0, "Hd {hd}");
}

#[test]
fn cli_diagnose_json_has_the_contract_fields() {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/shredder-table1");
    let v = json_ok(trackbelt_bin().args([
        "diagnose",
        data.to_str().unwrap(),
        "--variant",
        "E38",
        "--json",
    ]));
    assert_eq!(v["dataset"], "shredder-table1");
    // One row: it is the answer, with no verdict beside it.
    assert!(v["verdict"].is_null());
    let r = &v["results"][0];
    for k in [
        "series",
        "kind",
        "effect",
        "rms_before",
        "rms_after",
        "unit",
        "evidence",
    ] {
        assert!(!r[k].is_null(), "missing {k}");
    }
    let bad = trackbelt_bin()
        .args(["diagnose", "/nonexistent/dataset", "--json"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(bad.stdout.is_empty());
}

#[test]
fn cli_validate_diagnosis_json_keep_and_errors() {
    let keep = std::env::temp_dir().join(format!("trackbelt-validate-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&keep);
    let args = [
        "validate-diagnosis",
        "--count",
        "1",
        "--seed",
        "3",
        "--threads",
        "2",
        "--kind",
        "scroll",
        "--outcome",
        "none,wheel_runout",
        "--json",
        "--keep",
    ];
    let v = json_ok(trackbelt_bin().args(args).arg(&keep));
    let s = &v["summary"];
    assert_eq!(s["datasets"], 2);
    for k in [
        "right",
        "right_fraction",
        "wrong_names",
        "named",
        "near_noise_met",
    ] {
        assert!(s[k].is_number(), "summary.{k}");
    }
    let rows = v["matrix"]["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["outcome"], "none");
    assert_eq!(rows[1]["expected"], "unexplained");
    // No ceiling unless asked.
    assert!(v["datasets"][0]["evidence_ceiling"].is_null());
    assert_eq!(v["by_ceiling"].as_array().unwrap().len(), 0);
    // Nor rival ceilings unless asked.
    assert_eq!(
        v["datasets"][0]["rival_ceilings"].as_array().unwrap().len(),
        0
    );
    assert_eq!(v["by_separation"].as_array().unwrap().len(), 0);
    let cols = v["matrix"]["columns"].as_array().unwrap();
    assert_eq!(cols[0], "none");
    for r in rows {
        assert_eq!(r["counts"].as_array().unwrap().len(), cols.len());
    }
    assert!(keep.join("validate.json").is_file());
    assert!(keep.join("none-scroll-3").join("dataset.toml").is_file());
    assert!(keep.join("wheel_runout-scroll-3").is_dir());
    // --keep never overwrites.
    let again = trackbelt_bin().args(args).arg(&keep).output().unwrap();
    assert!(!again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("exists already"));
    // --again diagnoses the kept datasets again and writes nothing there.
    let report = std::fs::read(keep.join("validate.json")).unwrap();
    let v2 = json_ok(
        trackbelt_bin()
            .args(["validate-diagnosis", "--threads", "2", "--json", "--again"])
            .arg(&keep),
    );
    assert_eq!(v2["changed"].as_array().unwrap().len(), 0);
    assert_eq!(v2["right_before"], v["summary"]["right"]);
    assert_eq!(v2["report"]["summary"]["right"], v["summary"]["right"]);
    assert_eq!(
        v2["report"]["datasets"][1]["answer"],
        v["datasets"][1]["answer"]
    );
    assert_eq!(std::fs::read(keep.join("validate.json")).unwrap(), report);
    let text = trackbelt_bin()
        .args(["validate-diagnosis", "--again"])
        .arg(&keep)
        .output()
        .unwrap();
    assert!(text.status.success());
    assert!(String::from_utf8_lossy(&text.stdout).contains("0 answer(s) changed"));
    // --kind and --outcome keep only those kept datasets.
    let runout = json_ok(
        trackbelt_bin()
            .args(["validate-diagnosis", "--json", "--kind", "scroll"])
            .args(["--outcome", "wheel_runout", "--again"])
            .arg(&keep),
    );
    let kept = runout["report"]["datasets"].as_array().unwrap();
    assert_eq!(kept.len(), 1);
    assert_eq!(kept[0]["outcome"], "wheel_runout");
    let dynamic = trackbelt_bin()
        .args(["validate-diagnosis", "--kind", "dynamic", "--again"])
        .arg(&keep)
        .output()
        .unwrap();
    assert!(!dynamic.status.success());
    assert!(String::from_utf8_lossy(&dynamic.stderr).contains("no kept dataset"));
    // With nothing kept there: an error that names the file.
    let none = trackbelt_bin()
        .args(["validate-diagnosis", "--again"])
        .arg(keep.join("none-scroll-3"))
        .output()
        .unwrap();
    assert!(!none.status.success());
    assert!(String::from_utf8_lossy(&none.stderr).contains("validate.json"));
    // --again runs no new draw: it refuses the options that make one.
    let both = trackbelt_bin()
        .args(["validate-diagnosis", "--seed", "4", "--again"])
        .arg(&keep)
        .output()
        .unwrap();
    assert!(!both.status.success());
    let _ = std::fs::remove_dir_all(&keep);
    // Every effect at the magnitude asked (the detection-limit runs), with
    // its evidence ceiling: a bearing torque of this size stands far above
    // the logger's noise whatever the clean belt's fitted factors.
    let v = json_ok(trackbelt_bin().args([
        "validate-diagnosis",
        "--count",
        "1",
        "--seed",
        "3",
        "--threads",
        "1",
        "--outcome",
        "bearing_friction",
        "--magnitude",
        "1.5",
        "--ceiling",
        "--json",
    ]));
    assert_eq!(v["magnitude"], 1.5);
    assert_eq!(v["datasets"][0]["magnitude"], 1.5);
    let ceiling = v["datasets"][0]["evidence_ceiling"].as_f64().unwrap();
    assert!(ceiling > 100.0, "ceiling {ceiling}");
    let by = v["by_ceiling"].as_array().unwrap();
    assert_eq!(by.len(), 1);
    assert_eq!(by[0]["effect"], "bearing_friction");
    assert_eq!(by[0]["bins"][2][1], 1);
    let too_big = trackbelt_bin()
        .args(["validate-diagnosis", "--magnitude", "9"])
        .output()
        .unwrap();
    assert!(!too_big.status.success());
    assert!(String::from_utf8_lossy(&too_big.stderr).contains("magnitude 9"));
    let bad = trackbelt_bin()
        .args(["validate-diagnosis", "--outcome", "gremlins"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("gremlins"));
}

/// `--runs 2`: each dataset holds two runs of one belt, whose first is
/// the dataset a one-run validation draws at the same seed; the dataset
/// answers from both series (`diagnose` prints that verdict), and the
/// report scores the first run alone as well. Four scroll series, 1–4 s
/// each.
#[test]
fn cli_validate_diagnosis_with_two_runs_per_dataset() {
    let keep = std::env::temp_dir().join(format!("trackbelt-validate-runs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&keep);
    let args = [
        "validate-diagnosis",
        "--count",
        "1",
        "--seed",
        "3",
        "--threads",
        "2",
        "--kind",
        "scroll",
        "--outcome",
        "none,wheel_runout",
        "--json",
    ];
    let one = json_ok(trackbelt_bin().args(args));
    assert_eq!(one["runs_per_dataset"], 1);
    assert!(one["by_runs"].is_null(), "no per-run scores with one run");
    assert!(one["datasets"][0]["series_answers"].is_null());
    let two = json_ok(
        trackbelt_bin()
            .args(args)
            .args(["--runs", "2", "--keep"])
            .arg(&keep),
    );
    assert_eq!(two["runs_per_dataset"], 2);
    for (a, b) in one["datasets"]
        .as_array()
        .unwrap()
        .iter()
        .zip(two["datasets"].as_array().unwrap())
    {
        let answers = b["series_answers"].as_array().unwrap();
        assert_eq!(answers.len(), 2);
        // The first run is the one-run dataset: the same answer.
        assert_eq!(answers[0], a["answer"], "{}", b["evidence"]);
    }
    let by = two["by_runs"].as_array().unwrap();
    assert_eq!(by.len(), 2);
    assert_eq!(by[0]["right"], one["summary"]["right"]);
    assert_eq!(by[0]["wrong_names"], one["summary"]["wrong_names"]);
    assert_eq!(by[1]["right"], two["summary"]["right"]);
    assert_eq!(by[1]["wrong_names"], two["summary"]["wrong_names"]);
    // The kept dataset holds both runs, and `diagnose` gives the verdict.
    let dir = keep.join("wheel_runout-scroll-3");
    let toml = std::fs::read_to_string(dir.join("dataset.toml")).unwrap();
    assert_eq!(toml.matches("[[scroll]]").count(), 2);
    let d = json_ok(trackbelt_bin().arg("diagnose").arg(&dir).arg("--json"));
    assert_eq!(d["results"].as_array().unwrap().len(), 2);
    assert_eq!(d["verdict"]["effect"], two["datasets"][1]["answer"]);
    assert!(d["verdict"]["evidence"].as_str().unwrap().contains("run-2"));
    let text = trackbelt_bin().arg("diagnose").arg(&dir).output().unwrap();
    assert!(text.status.success());
    assert!(String::from_utf8_lossy(&text.stdout).contains("dataset verdict (2 series)"));
    let _ = std::fs::remove_dir_all(&keep);
    // At most six runs, and none with --again.
    let many = trackbelt_bin()
        .args(["validate-diagnosis", "--runs", "7"])
        .output()
        .unwrap();
    assert!(!many.status.success());
    let again = trackbelt_bin()
        .args(["validate-diagnosis", "--runs", "2", "--again", "/tmp"])
        .output()
        .unwrap();
    assert!(!again.status.success());
}

#[test]
fn cli_rig_out_of_range_speed_is_an_error_not_a_figure() {
    // Was: exit 0 with a 64.9 N·m mean torque.
    for speed in ["1e9", "29", "nan"] {
        let out = trackbelt_bin()
            .args([
                "rig",
                "--variant",
                "E56",
                "--method",
                "I",
                "--json",
                "--speed-rad-s",
                speed,
            ])
            .output()
            .unwrap();
        assert!(!out.status.success(), "{speed}: exit 0");
        assert!(out.stdout.is_empty(), "{speed}: printed a figure");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("drive speed"), "{speed}: {err}");
    }
    let help = trackbelt_bin().args(["rig", "--help"]).output().unwrap();
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(
        help.contains("Valid range") && help.contains("28.2"),
        "{help}"
    );
}

/// `synth --params` writes the file's belt (and `--roller-kg` the roller)
/// into the dataset, so `diagnose` reads the belt that was simulated
/// (issue 12: synth honours the belt); scroll datasets carry the rig's
/// centre distance for that belt.
#[test]
fn cli_synth_writes_the_simulated_belt_and_roller() {
    let dir = std::env::temp_dir().join(format!("trackbelt-synth-belt-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let params = dir.join("belt.toml");
    std::fs::write(
        &params,
        "version = 2\n\n[belt]\nlength_mm = 1500\nwidth_mm = 120\nthickness_mm = 6\n\
         mass_kg = 2.5\nlinks = 44\n\n[joint]\nmethod = \"I\"\nkz_nmm_per_rad = 3000\n\
         cz_nmms_per_rad = 150\n",
    )
    .unwrap();
    let out = trackbelt_bin()
        .args([
            "synth",
            "--duration-s",
            "1",
            "--roller-kg",
            "0.6",
            "--params",
        ])
        .arg(&params)
        .arg(dir.join("dyn"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(dir.join("dyn/dataset.toml")).unwrap();
    for line in [
        "length_mm = 1500",
        "mass_kg = 2.5",
        "grousers = 44",
        "roller_kg = 0.6",
    ] {
        assert!(text.contains(line), "no `{line}` in:\n{text}");
    }
    // A non-positive roller is refused; nothing is written.
    let out = trackbelt_bin()
        .args(["synth", "--roller-kg=0", "--params"])
        .arg(&params)
        .arg(dir.join("bad"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--roller-kg"));
    assert!(!dir.join("bad/dataset.toml").exists());
    // The default scroll rig (300 mm wheels) on the Shredder belt: the
    // open-belt centre distance on the belt's mid-plane.
    let out = trackbelt_bin()
        .args(["synth", "--kind", "scroll"])
        .arg(dir.join("scroll"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(dir.join("scroll/dataset.toml")).unwrap();
    assert!(text.contains("center_distance_mm = 741.2"), "{text}");
    assert!(text.contains("length_mm = 2450"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

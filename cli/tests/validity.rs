//! The binary's side of the validity checks: warnings on stderr and in the
//! JSON beside the figures, a failed check an error with a non-zero exit,
//! and the validity range in every simulating command's `--help`.

use std::process::Command;

fn trackbelt(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_trackbelt"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn a_short_test_warns_on_stderr_and_in_the_json() {
    let base = ["simulate", "--variant", "E38", "--method", "II"];
    let short = [&base[..], &["--duration-s", "1"]].concat();
    let out = trackbelt(&short);
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("warning: not settled"), "{err}");
    let out = trackbelt(&[&short[..], &["--json"]].concat());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["warnings"][0]
        .as_str()
        .unwrap()
        .starts_with("not settled"));
    assert!(v["hd_mm"].is_f64());
    // The default run has no "warnings" key at all.
    let out = trackbelt(&[&base[..], &["--json"]].concat());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v.get("warnings").is_none(), "{v}");
}

#[test]
fn a_coarse_step_is_flagged() {
    let out = trackbelt(&[
        "simulate",
        "--variant",
        "E38",
        "--method",
        "I",
        "--step-ms",
        "100",
        "--json",
    ]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let w: Vec<&str> = v["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|x| x.as_str())
        .collect();
    assert!(
        w.iter().any(|x| x.starts_with("time resolution"))
            && w.iter().any(|x| x.starts_with("step rejections")),
        "{w:?}"
    );
}

#[test]
fn every_simulating_command_states_its_validity_range() {
    for cmd in [
        "simulate",
        "paper",
        "bench",
        "calibrate",
        "diagnose",
        "synth",
        "rig",
    ] {
        let out = trackbelt(&[cmd, "--help"]);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("Validity range"), "{cmd}: {text}");
    }
}

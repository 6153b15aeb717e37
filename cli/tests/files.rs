//! Files: a malformed params file is an error naming its file and line
//! with a non-zero exit; no command writes into an input dataset; an
//! interrupted calibration leaves no output file (nor a temporary one).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn trackbelt_bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_trackbelt"))
}

fn repo(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(rel)
}

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("trackbelt-files-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Every file under `dir` with its bytes.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(p.clone(), std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// A copy of the shipped dataset `name` in a scratch directory.
fn dataset_copy(name: &str, tag: &str) -> PathBuf {
    let d = scratch(tag).join(name);
    std::fs::create_dir_all(&d).unwrap();
    for e in std::fs::read_dir(repo(&format!("data/{name}"))).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, d.join(p.file_name().unwrap())).unwrap();
    }
    d
}

#[test]
fn malformed_params_files_name_file_and_line_and_exit_non_zero() {
    let dir = scratch("params");
    let cases: [(&str, &str, &str); 3] = [
        (
            "unclosed.toml",
            "variant = \"E56\"\nmethod = \"III\"\n\n[stiffness]\nangles_deg = [1, 2\ntorques_nmm = [0]\n",
            "line 6",
        ),
        (
            "wrong-type.toml",
            "variant = \"E56\"\nmethod = \"III\"\n\n[stiffness]\nangles_deg = \"x\"\n",
            "line 5",
        ),
        ("garbage.toml", "method = I\n", "line 1"),
    ];
    for (name, text, line) in cases {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        for cmd in [
            vec![
                "simulate",
                "--variant",
                "E56",
                "--method",
                "III",
                "--json",
                "--params",
            ],
            vec![
                "rig",
                "--variant",
                "E56",
                "--method",
                "III",
                "--json",
                "--params",
            ],
        ] {
            let out = trackbelt_bin().args(&cmd).arg(&path).output().unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(!out.status.success(), "{name} {cmd:?}: exit 0");
            assert!(out.stdout.is_empty(), "{name}: printed {:?}", out.stdout);
            assert!(
                err.contains(name) && err.contains(line),
                "{name} {cmd:?}: {err}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn no_command_writes_into_an_input_dataset() {
    let ds = dataset_copy("shredder-table1", "ds-calib");
    let before = snapshot(&ds);
    // calibrate --out inside the dataset (directly, via `..`, in a
    // subdirectory that does not exist, over the manifest): refused.
    let outs = [
        ds.join("out.toml"),
        ds.join("../shredder-table1/out.toml"),
        ds.join("sub/out.toml"),
        ds.join("dataset.toml"),
    ];
    for out in &outs {
        let t = Instant::now();
        let o = trackbelt_bin()
            .arg("calibrate")
            .arg(&ds)
            .args(["--variant", "E38", "--out"])
            .arg(out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{}: exit 0", out.display());
        assert!(
            err.contains("refusing to write inside the dataset"),
            "{err}"
        );
        // Refused before the fit.
        assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
    }
    // diagnose --plot into the dataset: refused.
    for plot in [ds.clone(), ds.join("plots")] {
        let o = trackbelt_bin()
            .arg("diagnose")
            .arg(&ds)
            .arg("--plot")
            .arg(&plot)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{}: exit 0", plot.display());
        assert!(
            err.contains("refusing to write inside the dataset"),
            "{err}"
        );
    }
    // synth over an existing dataset: refused.
    let o = trackbelt_bin()
        .arg("synth")
        .arg(&ds)
        .args(["--seed", "1"])
        .output()
        .unwrap();
    assert!(!o.status.success(), "synth over a dataset: exit 0");
    assert_eq!(snapshot(&ds), before, "the dataset changed");
    let _ = std::fs::remove_dir_all(ds.parent().unwrap());
}

/// Sends SIGINT (Ctrl-C) to `pid` with the system's `kill`.
fn interrupt(pid: u32) -> bool {
    Command::new("kill")
        .args(["-INT", &pid.to_string()])
        .status()
        .map(|s| s.success())
        .unwrap_or(false)
}

#[test]
fn an_interrupted_calibration_leaves_no_output_file() {
    let dir = scratch("interrupt");
    let out = dir.join("params.toml");
    let mut cmd = trackbelt_bin();
    cmd.arg("calibrate")
        .arg(repo("data/shredder-table1"))
        .args(["--variant", "E56", "--threads", "1", "--out"])
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    // A shell without job control starts background jobs with SIGINT
    // ignored, and children inherit that (`.ci/run` launched with `&` from
    // a script failed here: the calibration ran to its end and exited 0).
    // Ctrl-C is what this test is about, so the child starts with
    // SIGINT's default disposition.
    #[cfg(unix)]
    {
        use std::os::unix::process::CommandExt;
        // SAFETY: between fork and exec the closure only calls `signal`,
        // which is async-signal-safe, and allocates nothing.
        unsafe {
            cmd.pre_exec(|| {
                libc::signal(libc::SIGINT, libc::SIG_DFL);
                Ok(())
            });
        }
    }
    let mut child = cmd.spawn().unwrap();
    std::thread::sleep(Duration::from_secs(1));
    let running = child.try_wait().unwrap().is_none();
    assert!(
        running,
        "the calibration finished within 1 s: nothing to interrupt"
    );
    if !interrupt(child.id()) {
        child.kill().unwrap();
    }
    let status = child.wait().unwrap();
    assert!(!status.success(), "interrupted calibration exited 0");
    assert!(
        !out.exists(),
        "an interrupted calibration left {}",
        out.display()
    );
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert!(left.is_empty(), "files left behind: {left:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

//! `beside KEPT_DIR OUT_DIR [--series]`: copy the scroll datasets a
//! `trackbelt validate-diagnosis --keep KEPT_DIR` run left (directories
//! `<outcome>-scroll-<seed>`, drawn without `--magnitude` or `--runs`)
//! into `OUT_DIR`, each with its belt's drop figures
//! ([`trackbelt_truth::drop_figures`]: static repeats and a drop test's
//! summary figures, no series) appended to its `dataset.toml`, and the
//! kept `validate.json` beside them (with `--series`, the drop test's
//! series too, as `dynamic-1.csv`: [`trackbelt_truth::drop_test_with_series`]), so that `trackbelt
//! validate-diagnosis --again OUT_DIR` scores the same rig runs with the
//! belt's drop figures beside them. Each series is checked byte for byte
//! against a fresh draw of its seed. Nothing in `OUT_DIR` is overwritten.
use std::path::Path;
use trackbelt_truth::*;

fn fail(msg: String) -> ! {
    eprintln!("beside: {msg}");
    std::process::exit(1);
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let with_series = a.len() == 4 && a[3] == "--series";
    if a.len() != 3 && !with_series {
        eprintln!("usage: beside KEPT_DIR OUT_DIR [--series]");
        std::process::exit(2);
    }
    let (src, dst) = (Path::new(&a[1]), Path::new(&a[2]));
    let read =
        |p: &Path| std::fs::read(p).unwrap_or_else(|e| fail(format!("{}: {e}", p.display())));
    let write = |p: &Path, bytes: &[u8]| {
        if p.exists() {
            fail(format!(
                "{} exists already: nothing is overwritten",
                p.display()
            ));
        }
        std::fs::write(p, bytes).unwrap_or_else(|e| fail(format!("{}: {e}", p.display())));
    };
    let mut names: Vec<String> = std::fs::read_dir(src)
        .unwrap_or_else(|e| fail(format!("{}: {e}", src.display())))
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.contains("-scroll-"))
        .collect();
    names.sort();
    std::fs::create_dir_all(dst).unwrap_or_else(|e| fail(format!("{}: {e}", dst.display())));
    for n in &names {
        let mut parts = n.rsplitn(3, '-');
        let (Some(seed), Some(_), Some(oname)) = (parts.next(), parts.next(), parts.next()) else {
            continue;
        };
        let (Ok(seed), Some(outcome)) = (seed.parse::<u64>(), Outcome::from_name(oname)) else {
            eprintln!("{n}: not a kept dataset's name, skipped");
            continue;
        };
        let sc =
            draw(outcome, SeriesKind::Scroll, seed).unwrap_or_else(|e| fail(format!("{n}: {e}")));
        // The dataset with the drop test beside the rig run, drawn afresh;
        // its rig series must be the kept one (no --magnitude, one run).
        let scratch = std::env::temp_dir().join(format!("beside-{}-{n}", std::process::id()));
        let drawn = generate_beside(&sc, &scratch, with_series);
        let kept_series = read(&src.join(n).join("scroll-1.csv"));
        let copied = drawn.map_err(|e| format!("{n}: {e}")).and_then(|truth| {
            if read(&scratch.join("scroll-1.csv")) != kept_series {
                return Err(format!("{n}: the kept series is not a fresh draw of seed {seed} (kept with --magnitude or --runs?)"));
            }
            let out = dst.join(n);
            std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
            for f in &truth.files {
                let name = f.file_name().ok_or_else(|| format!("{}: no file name", f.display()))?;
                write(&out.join(name), &read(f));
            }
            Ok(())
        });
        let _ = std::fs::remove_dir_all(&scratch);
        copied.unwrap_or_else(|e| fail(e));
        println!("{n}");
    }
    let report = src.join("validate.json");
    if report.exists() {
        write(&dst.join("validate.json"), &read(&report));
    }
}

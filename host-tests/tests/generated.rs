//! Generated-input tests (proptest, stable Rust): every parser and entry
//! point fed arbitrary or mutated input never panics; it returns a value or
//! a typed error (naming the file, for the file readers).
//!
//! Case counts are per test (see [`cases`]); CI runs the defaults (over
//! 10⁵ cases in all, well under a minute in release). Scale them with
//! `TRACKBELT_PROPTEST_SCALE` (a multiplier, e.g. `100`): the long campaign
//! is `host-tests/long-campaign.sh`. Failing inputs proptest finds are kept
//! in `host-tests/tests/generated.proptest-regressions` (replayed first on
//! every run); the ones found while writing these tests are also explicit
//! `#[test]`s at the end.

use proptest::prelude::*;
use proptest::test_runner::FileFailurePersistence;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use trackbelt::effects::{
    DahlFriction, Effects, JointFriction, PayneSoftening, RateDamping, ThermalSoftening,
};
use trackbelt::estimator::{EstimatorState, EstimatorTable, Status};
use trackbelt::joint::JointLaw;
use trackbelt::params::{Belt, Method, Model, Variant};
use trackbelt::rig::RigConfig;
use trackbelt::stiffness::{Stiffness, TorqueTable};
use trackbelt::{Fx, Real, Settings};
use trackbelt_host::params_file::{
    parse_system, AmplitudeStiffnessSection, BeltSection, ContactSection, DahlFrictionSection,
    EffectsSection, GearSection, GroundSection, JointFrictionSection, JointSection, ParamsFile,
    PayneSofteningSection, QuadraticDampingSection, RateDampingSection, SystemFile,
    TensionerSection, ThermalSofteningSection, WheelSection,
};

/// Base case counts of the tests, summed: the long campaign multiplies it by
/// its scale to report the cases it ran.
pub const BASE_CASES_TOTAL: u32 = 4_000 // dataset manifest
    + 2_000 // dataset series
    + 8_000 // params file text
    + 2_000 // params file on disk
    + 4_000 // params file version 2 text
    + 4_000 // params file version 2 generated
    + 20_000 // belt / model
    + 10_000 // joint law
    + 10_000 // torque table
    + 10_000 // effects
    + 10_000 // rig config
    + 10_000 // settings
    + 3_000 // estimator f64
    + 3_000 // estimator f32
    + 3_000 // estimator Fx
    + 5_000 // core figures
    + 3_000 // series figures
    + 3_000 // diagnosis signature
    + 48 // rig new
    + 2_000 // running-gear table f32
    + 2_000 // running-gear table Fx
    + 2_000 // monitor f32
    + 2_000 // monitor Fx
    + 10_000 // running-gear configuration
    + 12; // running gear on the rig

/// `base` scaled by `TRACKBELT_PROPTEST_SCALE` (default 1).
fn cases(base: u32) -> u32 {
    let scale: f64 = std::env::var("TRACKBELT_PROPTEST_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .filter(|s: &f64| s.is_finite() && *s > 0.0)
        .unwrap_or(1.0);
    ((base as f64 * scale).round() as u32).max(1)
}

fn config(base: u32) -> ProptestConfig {
    ProptestConfig {
        cases: cases(base),
        failure_persistence: Some(Box::new(FileFailurePersistence::WithSource(
            "proptest-regressions",
        ))),
        ..ProptestConfig::default()
    }
}

// ---------------------------------------------------------------------------
// Strategies
// ---------------------------------------------------------------------------

/// Any f64, with the awkward ones (NaN, ±inf, ±0, huge, tiny, negative)
/// drawn often.
fn wild_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => Just(f64::NAN),
        2 => Just(f64::INFINITY),
        2 => Just(f64::NEG_INFINITY),
        2 => Just(0.0),
        1 => Just(-0.0),
        2 => Just(f64::MAX),
        1 => Just(f64::MIN),
        1 => Just(f64::MIN_POSITIVE),
        1 => Just(5e-324),
        2 => Just(1e300),
        2 => Just(-1e300),
        6 => -1e6..1e6f64,
        6 => 1e-9..1e3f64,
        4 => (-300i32..300).prop_map(|e| 10f64.powi(e)),
        4 => any::<f64>(),
    ]
}

/// Usually a sane value near `nominal`, sometimes a wild one: the
/// constructors are exercised past their first check.
fn near(nominal: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => (0.01..100.0f64).prop_map(move |s| nominal * s),
        1 => wild_f64(),
    ]
}

/// A parameter of a physical size: 0 or 1e-6 ≤ |x| ≤ 1e6.
fn plausible(x: f64) -> bool {
    x == 0.0 || (1e-6..=1e6).contains(&x.abs())
}

fn law() -> JointLaw<f64> {
    trackbelt::params::paper::joint_law(Variant::E56, Method::I).unwrap()
}

// ---------------------------------------------------------------------------
// Mutated files in temporary directories
// ---------------------------------------------------------------------------

/// A fresh empty directory under the system's temp dir (removed on drop).
struct TempDir(PathBuf);

impl TempDir {
    fn new(tag: &str) -> TempDir {
        static N: AtomicUsize = AtomicUsize::new(0);
        let dir = std::env::temp_dir().join(format!(
            "trackbelt-gen-{tag}-{}-{}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Replacement values for a `key = value` line: wrong types, out of range,
/// NaN, huge, empty, unterminated.
const BAD_VALUES: &[&str] = &[
    "nan",
    "-nan",
    "inf",
    "-inf",
    "0",
    "-0.0",
    "-1",
    "-1e300",
    "1e308",
    "1e309",
    "99999999999999999999999",
    "-9223372036854775809",
    "18446744073709551616",
    "4294967296",
    "1e-320",
    "\"x\"",
    "\"\"",
    "\"../../etc/passwd\"",
    "\"/\"",
    "\"dataset.toml\"",
    "\".\"",
    "[]",
    "[1, \"a\"]",
    "{}",
    "{ a = 1 }",
    "true",
    "1979-05-27T07:32:00Z",
    "\"unterminated",
    "",
    "= =",
    "0x10",
    "1_000",
    "+1",
];

/// Replacement cells for a CSV field.
const BAD_CELLS: &[&str] = &[
    "",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e309",
    "-1e308",
    "x",
    "0",
    "-0",
    "1e-320",
    "\"1\"",
    "1,2",
    " 1 ",
    "--1",
    "1e",
    "0x1",
    "\u{feff}1",
];

/// One edit of a text file, line based or byte based.
#[derive(Debug, Clone)]
enum Edit {
    DropLine(usize),
    DuplicateLine(usize),
    SwapLines(usize, usize),
    ReplaceValue(usize, usize),
    ReplaceCell(usize, usize, usize),
    Truncate(usize),
    InsertBytes(usize, Vec<u8>),
    FlipByte(usize, u8),
    InsertLine(usize, String),
}

fn edit() -> impl Strategy<Value = Edit> {
    let idx = any::<usize>();
    prop_oneof![
        3 => idx.prop_map(Edit::DropLine),
        2 => idx.prop_map(Edit::DuplicateLine),
        1 => (idx, idx).prop_map(|(a, b)| Edit::SwapLines(a, b)),
        5 => (idx, 0..BAD_VALUES.len()).prop_map(|(a, b)| Edit::ReplaceValue(a, b)),
        4 => (idx, idx, 0..BAD_CELLS.len()).prop_map(|(a, b, c)| Edit::ReplaceCell(a, b, c)),
        1 => idx.prop_map(Edit::Truncate),
        1 => (idx, proptest::collection::vec(any::<u8>(), 1..8))
            .prop_map(|(a, b)| Edit::InsertBytes(a, b)),
        1 => (idx, any::<u8>()).prop_map(|(a, b)| Edit::FlipByte(a, b)),
        2 => (idx, "[a-z_\\[\\]\\.= \"0-9,-]{0,24}").prop_map(|(a, s)| Edit::InsertLine(a, s)),
    ]
}

/// Applies `edits` to `text` (indices taken modulo the sizes).
fn mutate(text: &str, edits: &[Edit]) -> Vec<u8> {
    let mut bytes = text.as_bytes().to_vec();
    for e in edits {
        let s = String::from_utf8_lossy(&bytes).into_owned();
        let mut lines: Vec<String> = s.split('\n').map(str::to_owned).collect();
        let n = lines.len().max(1);
        match e {
            Edit::DropLine(i) => {
                if !lines.is_empty() {
                    lines.remove(i % n);
                }
            }
            Edit::DuplicateLine(i) => {
                if !lines.is_empty() {
                    let l = lines[i % n].clone();
                    lines.insert(i % n, l);
                }
            }
            Edit::SwapLines(a, b) => {
                if !lines.is_empty() {
                    lines.swap(a % n, b % n);
                }
            }
            Edit::ReplaceValue(i, v) => {
                if let Some(l) = lines.get_mut(i % n) {
                    if let Some(eq) = l.find('=') {
                        l.truncate(eq + 1);
                        l.push(' ');
                        l.push_str(BAD_VALUES[*v]);
                    } else {
                        *l = BAD_VALUES[*v].to_owned();
                    }
                }
            }
            Edit::ReplaceCell(i, c, v) => {
                if let Some(l) = lines.get_mut(i % n) {
                    let mut cells: Vec<String> = l.split(',').map(str::to_owned).collect();
                    let k = c % cells.len();
                    cells[k] = BAD_CELLS[*v].to_owned();
                    *l = cells.join(",");
                }
            }
            Edit::InsertLine(i, t) => lines.insert(i % n, t.clone()),
            Edit::Truncate(i) => {
                bytes.truncate(i % (bytes.len() + 1));
                continue;
            }
            Edit::InsertBytes(i, b) => {
                let at = i % (bytes.len() + 1);
                bytes.splice(at..at, b.iter().copied());
                continue;
            }
            Edit::FlipByte(i, b) => {
                if !bytes.is_empty() {
                    let k = i % bytes.len();
                    bytes[k] ^= b | 1;
                }
                continue;
            }
        }
        bytes = lines.join("\n").into_bytes();
    }
    bytes
}

fn repo_path(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)
}

/// A shipped dataset: directory name, manifest text, series files (name,
/// bytes).
type ShippedDataset = (String, String, Vec<(String, Vec<u8>)>);

/// The shipped datasets.
fn datasets() -> Vec<ShippedDataset> {
    [
        "shredder-table1",
        "synthetic-joint-friction",
        "synthetic-scroll-bearing",
    ]
    .iter()
    .map(|name| {
        let dir = repo_path(&format!("data/{name}"));
        let manifest = std::fs::read_to_string(dir.join("dataset.toml")).unwrap();
        let mut series = Vec::new();
        for e in std::fs::read_dir(&dir).unwrap() {
            let e = e.unwrap();
            let f = e.file_name().to_string_lossy().into_owned();
            if f.ends_with(".csv") {
                series.push((f, std::fs::read(e.path()).unwrap()));
            }
        }
        series.sort();
        (name.to_string(), manifest, series)
    })
    .collect()
}

/// Loads the dataset in `dir`; on error, checks the message names a file
/// of the dataset (and a line, where the error has one).
fn load_and_check(dir: &Path) -> Result<(), TestCaseError> {
    use trackbelt_host::dataset::DatasetError;
    match trackbelt_host::dataset::load(dir) {
        Ok(ds) => {
            // A loaded dataset reports finite figures only.
            let _ = format!("{ds:?}");
            Ok(())
        }
        Err(e) => {
            let msg = e.to_string();
            prop_assert!(
                msg.contains(&dir.display().to_string()),
                "error does not name a file of the dataset: {msg}"
            );
            if let DatasetError::Manifest { line: Some(l), .. }
            | DatasetError::Series { line: Some(l), .. } = &e
            {
                prop_assert!(msg.contains(&format!(":{l}")), "no line in: {msg}");
            }
            Ok(())
        }
    }
}

proptest! {
    #![proptest_config(config(4_000))]

    /// Mutated manifests (with the shipped series files beside them).
    #[test]
    fn dataset_manifest_mutations(which in 0..3usize, edits in proptest::collection::vec(edit(), 1..5)) {
        let sets = datasets();
        let (name, manifest, series) = &sets[which];
        let dir = TempDir::new(name);
        std::fs::write(dir.0.join("dataset.toml"), mutate(manifest, &edits)).unwrap();
        for (f, b) in series {
            std::fs::write(dir.0.join(f), b).unwrap();
        }
        load_and_check(&dir.0)?;
    }
}

proptest! {
    #![proptest_config(config(2_000))]

    /// Mutated series CSV files (with the shipped manifest).
    #[test]
    fn dataset_series_mutations(which in 1..3usize, edits in proptest::collection::vec(edit(), 1..6)) {
        let sets = datasets();
        let (name, manifest, series) = &sets[which];
        let dir = TempDir::new(name);
        std::fs::write(dir.0.join("dataset.toml"), manifest).unwrap();
        for (f, b) in series {
            let text = String::from_utf8_lossy(b);
            std::fs::write(dir.0.join(f), mutate(&text, &edits)).unwrap();
        }
        load_and_check(&dir.0)?;
    }
}

proptest! {
    #![proptest_config(config(8_000))]

    /// Mutated params files, parsed from text.
    #[test]
    fn params_file_text_mutations(v in 0..3usize, edits in proptest::collection::vec(edit(), 1..5)) {
        let variant = [Variant::E38, Variant::E56, Variant::E76][v];
        let text = trackbelt_host::params_file::shipped_text(variant);
        let bytes = mutate(text, &edits);
        let text = String::from_utf8_lossy(&bytes);
        let path = Path::new("/nonexistent/mutated-params.toml");
        if let Err(e) = ParamsFile::parse(&text, path) {
            let msg = e.to_string();
            prop_assert!(msg.contains("mutated-params.toml"), "no file in: {msg}");
        }
    }
}

proptest! {
    #![proptest_config(config(2_000))]

    /// Mutated params files on disk (bytes, not necessarily UTF-8).
    #[test]
    fn params_file_load_mutations(v in 0..3usize, edits in proptest::collection::vec(edit(), 1..5)) {
        let variant = [Variant::E38, Variant::E56, Variant::E76][v];
        let text = trackbelt_host::params_file::shipped_text(variant);
        let dir = TempDir::new("params");
        let path = dir.0.join("params.toml");
        std::fs::write(&path, mutate(text, &edits)).unwrap();
        match ParamsFile::load(&path) {
            Ok((_, law)) => prop_assert!(law.validate().is_ok()),
            Err(e) => {
                let msg = e.to_string();
                prop_assert!(msg.contains(&path.display().to_string()), "no file in: {msg}");
            }
        }
    }
}

/// A version 2 params file: a belt, a method III law with effects and a
/// four-wheel running gear on the ground.
const ROBOT_V2: &str = r#"version = 2

[belt]
length_mm = 1500
width_mm = 120
thickness_mm = 6
mass_kg = 2.5
links = 44

[joint]
method = "III"
angles_deg = [-44, -29, -6, 0, 3, 13]
torques_nmm = [-17000, -4200, -1600, 0, 970, 10100]
cz_nmms_per_rad = 430

[joint.effects.joint_friction]
torque_nm = 0.02

[joint.effects.thermal_softening]
alpha_per_k = 0.005
reference_temp_c = 20
temp_c = 35

[running_gear]
bearing_friction_nm = 0.1

[running_gear.tensioner]
force_n = 400

[[running_gear.wheels]]
role = "drive"
x_mm = 0
y_mm = 0
diameter_mm = 160

[[running_gear.wheels]]
role = "idler"
x_mm = 520
y_mm = 0
diameter_mm = 140

[[running_gear.wheels]]
role = "road"
x_mm = 170
y_mm = -60
diameter_mm = 90

[[running_gear.wheels]]
role = "road"
x_mm = 350
y_mm = -60
diameter_mm = 90

[running_gear.ground]
load_kg = 12

[running_gear.contact]
drive_friction = 0.8
"#;

/// What a parsed system must satisfy: every part valid.
fn check_system(sys: &trackbelt_host::params_file::System) -> Result<(), TestCaseError> {
    prop_assert!(sys.law.validate().is_ok());
    prop_assert!(sys.belt.validate().is_ok());
    prop_assert!((3..=trackbelt_host::params_file::MAX_LINKS).contains(&sys.belt.links));
    if let Some(g) = &sys.gear {
        prop_assert!(g.validate().is_ok());
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(4_000))]

    /// Mutated version 2 params files, parsed from text.
    #[test]
    fn params_v2_text_mutations(edits in proptest::collection::vec(edit(), 1..5)) {
        let bytes = mutate(ROBOT_V2, &edits);
        let text = String::from_utf8_lossy(&bytes);
        let path = Path::new("/nonexistent/mutated-v2.toml");
        match parse_system(&text, path) {
            Ok(sys) => check_system(&sys)?,
            Err(e) => {
                let msg = e.to_string();
                prop_assert!(msg.contains("mutated-v2.toml"), "no file in: {msg}");
            }
        }
        // The law-only reader agrees.
        let _ = ParamsFile::parse(&text, path);
    }
}

/// A generated version 2 document: sane values near a small robot's, wild
/// ones now and then, optional parts present or not.
fn v2_file() -> impl Strategy<Value = SystemFile> {
    let belt = (
        near(1500.0),
        near(120.0),
        near(6.0),
        near(2.5),
        prop_oneof![3 => (0i64..200).prop_map(Some), 1 => Just(None)],
        proptest::option::of(near(34.0)),
    )
        .prop_map(|(l, w, t, m, links, pitch)| BeltSection {
            length_mm: l,
            width_mm: w,
            thickness_mm: t,
            mass_kg: m,
            links: links.or(if pitch.is_none() { Some(44) } else { None }),
            grouser_pitch_mm: pitch,
        });
    let joint = (
        0..4usize,
        near(8600.0),
        near(40000.0),
        near(430.0),
        near(1.0),
    )
        .prop_map(|(m, k1, k2, cz, s)| {
            let mut j = JointSection {
                method: ["I", "II", "III", "IV"][m].into(),
                kz_nmm_per_rad: None,
                kz_pos_nmm_per_rad: None,
                kz_neg_nmm_per_rad: None,
                angles_deg: None,
                torques_nmm: None,
                cz_nmms_per_rad: cz,
                effects: EffectsSection::default(),
            };
            match m {
                0 => j.kz_nmm_per_rad = Some(k1),
                1 => {
                    j.kz_pos_nmm_per_rad = Some(k2);
                    j.kz_neg_nmm_per_rad = Some(k1);
                }
                _ => {
                    j.angles_deg = Some(vec![-44.0, -29.0, -6.0, 0.0, 3.0, 13.0]);
                    j.torques_nmm = Some(
                        [-17000.0, -4200.0, -1600.0, 0.0, 970.0, 10100.0]
                            .iter()
                            .map(|t| t * s)
                            .collect(),
                    );
                }
            }
            j
        });
    let effects = (
        proptest::option::of((near(0.02), near(0.01))),
        proptest::option::of(near(0.3)),
        proptest::option::of(near(3.0)),
        proptest::option::of((near(0.1), near(0.5), near(0.01))),
        proptest::option::of((near(0.005), near(20.0), proptest::option::of(near(35.0)))),
        proptest::option::of((near(0.02), near(0.006))),
        proptest::option::of((near(0.3), near(0.03), near(0.5), near(1.2))),
    )
        .prop_map(|(f, q, a, r, t, d, p)| EffectsSection {
            dahl_friction: d.map(|(torque_nm, presliding_rad)| DahlFrictionSection {
                torque_nm,
                presliding_rad,
            }),
            payne_softening: p.map(|(depth, amplitude_rad, memory_s, mean_s)| {
                PayneSofteningSection {
                    depth,
                    amplitude_rad,
                    memory_s,
                    mean_s,
                }
            }),
            joint_friction: f.map(|(torque_nm, smoothing_rad_s)| JointFrictionSection {
                torque_nm,
                smoothing_rad_s,
            }),
            quadratic_damping: q
                .map(|c2_nms2_per_rad2| QuadraticDampingSection { c2_nms2_per_rad2 }),
            amplitude_stiffness: a
                .map(|k3_nm_per_rad3| AmplitudeStiffnessSection { k3_nm_per_rad3 }),
            rate_dependent_damping: r.map(|(coefficient, exponent, smoothing_rad_s)| {
                RateDampingSection {
                    coefficient,
                    exponent,
                    smoothing_rad_s,
                }
            }),
            thermal_softening: t.map(|(alpha_per_k, reference_temp_c, temp_c)| {
                ThermalSofteningSection {
                    alpha_per_k,
                    reference_temp_c,
                    temp_c,
                }
            }),
        });
    let wheel =
        (0..5usize, near(200.0), near(50.0), near(120.0)).prop_map(|(r, x, y, d)| WheelSection {
            role: ["drive", "idler", "road", "support", "sprocket"][r].into(),
            x_mm: x,
            y_mm: y,
            diameter_mm: d,
        });
    // Usually a valid layout (drive, idler, road wheels on the ground),
    // with generated extra wheels now and then.
    let gear = (
        near(400.0),
        0..4usize,
        proptest::collection::vec(wheel, 0..8),
        near(0.1),
        proptest::option::of(near(12.0)),
        proptest::option::of(near(0.8)),
    )
        .prop_map(|(force, tens, extra, bearing, load, mu)| {
            let w = |role: &str, x: f64, y: f64, d: f64| WheelSection {
                role: role.into(),
                x_mm: x,
                y_mm: y,
                diameter_mm: d,
            };
            let mut wheels = vec![w("drive", 0.0, 0.0, 160.0), w("idler", 520.0, 0.0, 140.0)];
            if load.is_some() {
                wheels.push(w("road", 170.0, -60.0, 90.0));
            }
            if tens == 3 {
                wheels.extend(extra);
            }
            GearSection {
                bearing_friction_nm: bearing,
                tensioner: TensionerSection {
                    force_n: (tens != 1).then_some(force),
                    fixed_centre: (tens >= 1).then_some(tens == 1),
                },
                wheels,
                ground: load.map(|load_kg| GroundSection { load_kg }),
                contact: mu.map(|m| ContactSection {
                    drive_friction: Some(m),
                    ..ContactSection::default()
                }),
            }
        });
    (
        proptest::option::of(belt),
        joint,
        effects,
        proptest::option::of(gear),
        proptest::option::of(0..4usize),
    )
        .prop_map(|(belt, mut joint, effects, running_gear, v)| {
            joint.effects = effects;
            SystemFile {
                version: 2,
                variant: v.map(|v| ["E38", "E56", "E76", "E99"][v].to_string()),
                belt,
                joint,
                running_gear,
            }
        })
}

proptest! {
    #![proptest_config(config(4_000))]

    /// Generated version 2 documents: a valid one reads back to a valid
    /// system whose written text is a fixed point of read and write (after
    /// the first, the metres–millimetres and degrees–radians round trips
    /// settle); an invalid one is an error naming the file.
    #[test]
    fn params_v2_generated(file in v2_file()) {
        let Ok(text) = file.to_toml() else { return Ok(()) };
        let path = Path::new("/nonexistent/generated-v2.toml");
        match parse_system(&text, path) {
            Ok(s1) => {
                check_system(&s1)?;
                let s2 = parse_system(&s1.to_toml().unwrap(), path).unwrap();
                let s3 = parse_system(&s2.to_toml().unwrap(), path).unwrap();
                prop_assert_eq!(s2.belt, s3.belt);
                prop_assert_eq!(&s2.gear, &s3.gear);
                prop_assert_eq!(s2.method, s3.method);
                prop_assert_eq!(s2.law.effects, s3.law.effects);
                let rel = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs());
                prop_assert!(rel(s1.law.damping, s3.law.damping));
                prop_assert!(rel(s1.belt.length_m, s2.belt.length_m));
                prop_assert_eq!(s1.belt.links, s2.belt.links);
                for z in [-0.7, -0.3, -0.05, 0.02, 0.2] {
                    let (a, b) = (s1.law.stiffness.eval(z).0, s3.law.stiffness.eval(z).0);
                    prop_assert!((a - b).abs() <= 1e-9 * (1.0 + a.abs()), "{} {} {}", z, a, b);
                }
            }
            Err(e) => {
                let msg = e.to_string();
                prop_assert!(msg.contains("generated-v2.toml"), "no file in: {msg}");
            }
        }
    }
}

// ---------------------------------------------------------------------------
// The core's constructors
// ---------------------------------------------------------------------------

proptest! {
    #![proptest_config(config(20_000))]

    #[test]
    fn belt_and_model(length in near(2.45), width in near(0.16), thick in near(0.008),
                      mass in near(6.4), links in prop_oneof![0..200usize, any::<usize>()]) {
        let belt = Belt { length_m: length, width_m: width, thickness_m: thick, mass_kg: mass, links };
        let _ = belt.validate();
        if let Ok(m) = Model::new(belt, law()) {
            prop_assert!(m.validate().is_ok());
            prop_assert!(m.belt.link_length_m().is_finite() && m.belt.link_length_m() > 0.0);
            prop_assert!(m.belt.link_mass_kg().is_finite() && m.belt.link_mass_kg() > 0.0);
            // The narrower types.
            let _ = m.cast::<f32>().validate();
            let _ = m.cast::<Fx>().validate();
        }
    }
}

proptest! {
    #![proptest_config(config(10_000))]

    #[test]
    fn joint_law(kind in 0..3usize, a in near(15.0), b in near(40.0), c in near(0.5), zeta in wild_f64(), rate in wild_f64()) {
        let s = match kind {
            0 => Stiffness::Constant { kz: a },
            1 => Stiffness::Bivalent { kz_pos: a, kz_neg: b },
            _ => match TorqueTable::new(&[-0.3, -0.1, 0.0, 0.1], &[-a, -b, 0.0, a]) {
                Ok(t) => Stiffness::Table(t),
                Err(_) => return Ok(()),
            },
        };
        if let Ok(law) = JointLaw::new(s, c) {
            // A valid law evaluates without panicking anywhere.
            let _ = law.moment(zeta, rate);
            let _ = law.damping_power_w(zeta, rate);
            let m = law.moment(zeta.clamp(-1.0, 1.0), rate.clamp(-100.0, 100.0));
            // Finite output for parameters of a physical size (absurd but
            // finite ones, e.g. cz = 1e308, may overflow: no panic).
            if [a, b, c].iter().all(|x| plausible(*x)) && zeta.is_finite() && rate.is_finite() {
                prop_assert!(m.moment_nm.is_finite(), "{law:?} at {zeta} {rate}: {m:?}");
            }
            let _ = law.cast::<f32>().validate();
            let _ = law.cast::<Fx>().moment(Fx::from_f64(zeta), Fx::from_f64(rate));
        }
    }

    #[test]
    fn torque_table(angles in proptest::collection::vec(wild_f64(), 0..40),
                    torques in proptest::collection::vec(wild_f64(), 0..40),
                    sorted in any::<bool>(), zeta in wild_f64()) {
        let mut angles = angles;
        let mut torques = torques;
        if sorted {
            angles.retain(|x| !x.is_nan());
            angles.sort_by(|a, b| a.partial_cmp(b).unwrap());
            torques.retain(|x| !x.is_nan());
            torques.sort_by(|a, b| a.partial_cmp(b).unwrap());
            let n = angles.len().min(torques.len());
            angles.truncate(n);
            torques.truncate(n);
        }
        if let Ok(t) = TorqueTable::new(&angles, &torques) {
            let _ = t.eval(zeta);
            let (f, d) = t.eval(0.0);
            prop_assert!(f.is_finite() && d.is_finite(), "{t:?}: {f} {d}");
            let _ = t.cast::<f32>();
            let _ = t.cast::<Fx>().eval(Fx::from_f64(zeta));
            let _ = JointLaw::new(Stiffness::Table(t), 0.5);
        }
        // f32 and Fx tables too.
        let a32: Vec<f32> = angles.iter().map(|&x| x as f32).collect();
        let t32: Vec<f32> = torques.iter().map(|&x| x as f32).collect();
        let _ = TorqueTable::new(&a32, &t32).map(|t| t.eval(zeta as f32));
        let ax: Vec<Fx> = angles.iter().map(|&x| Fx::from_f64(x)).collect();
        let tx: Vec<Fx> = torques.iter().map(|&x| Fx::from_f64(x)).collect();
        let _ = TorqueTable::new(&ax, &tx).map(|t| t.eval(Fx::from_f64(zeta)));
    }

    #[test]
    fn effects(mask in 0u8..128, v in proptest::collection::vec(near(1.0), 17), zeta in wild_f64(), rate in wild_f64()) {
        let e = Effects {
            joint_friction: (mask & 1 != 0).then_some(JointFriction { torque_nm: v[0], smoothing_rad_s: v[1] }),
            quadratic_damping: (mask & 2 != 0).then_some(v[2]),
            amplitude_stiffness: (mask & 4 != 0).then_some(v[3]),
            rate_dependent_damping: (mask & 8 != 0).then_some(RateDamping { coefficient: v[4], exponent: v[5], smoothing_rad_s: v[6] }),
            thermal_softening: (mask & 16 != 0).then_some(ThermalSoftening { alpha_per_k: v[7] * 1e-3, reference_temp_c: v[8] * 20.0, temp_c: v[9] * 20.0 }),
            dahl_friction: (mask & 32 != 0).then_some(DahlFriction { torque_nm: v[11] * 0.02, presliding_rad: v[12] * 0.006 }),
            payne_softening: (mask & 64 != 0).then_some(PayneSoftening { depth: v[13] * 0.3, amplitude_rad: v[14] * 0.03, memory_s: v[15] * 0.5, mean_s: v[16] * 1.2 }),
        };
        if e.validate().is_ok() {
            // The memory laws' kernels stay finite on every valid law and
            // finite input: the friction within ±Mc of a state inside it.
            if let (Some(d), true) = (&e.dahl_friction, zeta.is_finite()) {
                let (m, slope) = d.advance(0.5 * d.torque_nm, zeta);
                prop_assert!(m.is_finite() && slope.is_finite() && slope >= 0.0, "{d:?} {zeta}");
                prop_assert!(m.abs() <= d.torque_nm * (1.0 + 1e-12), "{d:?} {zeta}: {m}");
            }
            if let (Some(p), true) = (&e.payne_softening, zeta.is_finite()) {
                // The arm about the mean is never softer than the static
                // law (h ≥ 1) and at most the law's end value.
                let g = p.factor(zeta);
                let top = (1.0 / (1.0 - p.depth)).max(1.0 - p.depth);
                prop_assert!(g >= 1.0 && g <= top * (1.0 + 1e-12), "{p:?} {zeta}: {g}");
            }
            let m = law().moment(0.1, 1.0);
            let out = e.apply(zeta.clamp(-1.0, 1.0), rate.clamp(-100.0, 100.0), m);
            if v.iter().all(|x| plausible(*x)) && zeta.is_finite() && rate.is_finite() {
                prop_assert!(out.moment_nm.is_finite(), "{e:?}: {out:?}");
            }
            let _ = e.apply(zeta, rate, m);
            let _ = e.cast::<f32>().validate();
            let _ = e.cast::<Fx>().validate();
        }
    }

    #[test]
    fn rig_config(v in proptest::collection::vec(near(1.0), 10)) {
        let d = RigConfig::<f64>::default();
        let c = RigConfig {
            drive_diameter_m: d.drive_diameter_m * v[0],
            idler_diameter_m: d.idler_diameter_m * v[1],
            idler_force_n: d.idler_force_n * v[2],
            idler_mass_kg: d.idler_mass_kg * v[3],
            idler_damping_n_s_per_m: d.idler_damping_n_s_per_m * v[4],
            wheel_stiffness_n_per_m: d.wheel_stiffness_n_per_m * v[5],
            wheel_damping_n_s_per_m: d.wheel_damping_n_s_per_m * v[6],
            drive_friction: d.drive_friction * v[7],
            slip_speed_m_s: d.slip_speed_m_s * v[8],
            bearing_friction_nm: v[9] - 1.0,
        };
        let _ = c.validate();
        let _ = c.cast::<f32>().validate();
        let _ = c.cast::<Fx>().validate();
    }

    #[test]
    fn settings(v in proptest::collection::vec(wild_f64(), 5), n in proptest::collection::vec(prop_oneof![0..100usize, any::<usize>()], 3)) {
        let s = Settings {
            step_s: v[0],
            min_step_s: v[1],
            newton_iterations: n[0],
            position_tol_m: v[2],
            angle_tol_rad: v[3],
            static_tau_max_s: v[4],
            static_iterations: n[1],
            relax_step_s: v[0] * 2.5,
            relax_steps: n[2],
            relax_creep_steps: n[1],
        };
        let _ = s.validate();
        let s32 = Settings::<f32> {
            step_s: v[0] as f32,
            min_step_s: v[1] as f32,
            newton_iterations: n[0],
            position_tol_m: v[2] as f32,
            angle_tol_rad: v[3] as f32,
            static_tau_max_s: v[4] as f32,
            static_iterations: n[1],
            relax_step_s: v[0] as f32,
            relax_steps: n[2],
            relax_creep_steps: n[1],
        };
        let _ = s32.validate();
    }
}

proptest! {
    #![proptest_config(config(48))]

    /// The rig itself (a static solve per case, so few cases): a config
    /// that validates builds or fails with a typed error, never a panic.
    #[test]
    fn rig_new(v in proptest::collection::vec(prop_oneof![3 => 0.2..5.0f64, 1 => near(1.0)], 4)) {
        use trackbelt::rig::Rig;
        let d = RigConfig::<f64>::default();
        let c = RigConfig {
            drive_diameter_m: d.drive_diameter_m * v[0],
            idler_diameter_m: d.idler_diameter_m * v[1],
            idler_force_n: d.idler_force_n * v[2],
            drive_friction: d.drive_friction * v[3],
            ..d
        };
        let mut b = Belt::<f64>::shredder(24);
        b.links = 24;
        let model = Model::new(b, law()).unwrap();
        let _ = Rig::<f64, 32>::new(model, c, Settings::default());
    }
}

// ---------------------------------------------------------------------------
// The estimator
// ---------------------------------------------------------------------------

fn table() -> &'static EstimatorTable<f64> {
    use std::sync::OnceLock;
    static T: OnceLock<EstimatorTable<f64>> = OnceLock::new();
    T.get_or_init(|| {
        trackbelt_host::firmware::estimator_table(&repo_path("params/E56.toml"))
            .unwrap()
            .table
    })
}

/// A speed/tick sample: mostly plausible, often wild.
fn sample() -> impl Strategy<Value = (f64, f64)> {
    (
        prop_oneof![4 => -40.0..40.0f64, 1 => wild_f64()],
        prop_oneof![4 => Just(1e-3), 2 => 1e-5..0.1f64, 1 => wild_f64()],
    )
}

fn run_estimator<T: Real>(samples: &[(f64, f64)]) -> Result<(), TestCaseError> {
    let table = table().cast::<T>();
    let mut state = EstimatorState::<T>::new();
    for &(w, dt) in samples {
        let (wt, dtt) = (T::from_f64(w), T::from_f64(dt));
        let e = table.update(&mut state, wt, dtt);
        prop_assert!(
            e.torque_nm.is_finite() && e.bending_nm.is_finite(),
            "not finite at speed {w} tick {dt}: {e:?}"
        );
        if !wt.is_finite() {
            prop_assert!(e.status.contains(Status::SPEED_NOT_FINITE));
        }
        if !(dtt.is_finite() && dtt > T::ZERO) && wt.is_finite() {
            prop_assert!(e.status.contains(Status::BAD_TICK), "{w} {dt}: {e:?}");
        }
        if wt.is_finite() && wt.abs() > table.max_speed_rad_s() {
            prop_assert!(e.status.contains(Status::SPEED_OUT_OF_RANGE), "{w}: {e:?}");
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(3_000))]

    #[test]
    fn estimator_f64(s in proptest::collection::vec(sample(), 1..64)) {
        run_estimator::<f64>(&s)?;
    }
}

proptest! {
    #![proptest_config(config(3_000))]

    #[test]
    fn estimator_f32(s in proptest::collection::vec(sample(), 1..64)) {
        run_estimator::<f32>(&s)?;
    }
}

proptest! {
    #![proptest_config(config(3_000))]

    #[test]
    fn estimator_fx(s in proptest::collection::vec(sample(), 1..64)) {
        run_estimator::<Fx>(&s)?;
    }
}

// ---------------------------------------------------------------------------
// Period and decrement extraction
// ---------------------------------------------------------------------------

/// A signal: a damped oscillation with noise, or arbitrary values, with
/// times that may repeat, go backwards or be NaN.
fn signal() -> impl Strategy<Value = (Vec<f64>, Vec<f64>)> {
    let damped = (
        0.1..5.0f64,
        0.0..3.0f64,
        0.0..100.0f64,
        0.001..0.1f64,
        50..2000usize,
        proptest::collection::vec(-1.0..1.0f64, 0..16),
    )
        .prop_map(|(period, decay, amp, dt, n, noise)| {
            let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
            let h: Vec<f64> = t
                .iter()
                .enumerate()
                .map(|(i, &t)| {
                    300.0
                        + amp * (-decay * t).exp() * (2.0 * std::f64::consts::PI * t / period).cos()
                        + noise.get(i % noise.len().max(1)).copied().unwrap_or(0.0)
                })
                .collect();
            (t, h)
        });
    let wild = (
        proptest::collection::vec(wild_f64(), 0..200),
        proptest::collection::vec(wild_f64(), 0..200),
    );
    let sorted_wild = proptest::collection::vec((1e-4..1.0f64, wild_f64()), 0..300).prop_map(|v| {
        let mut t = 0.0;
        v.into_iter()
            .map(|(dt, h)| {
                t += dt;
                (t, h)
            })
            .unzip()
    });
    prop_oneof![3 => damped, 1 => wild, 2 => sorted_wild]
}

fn finite_or_none(x: Option<f64>) -> bool {
    x.is_none_or(f64::is_finite)
}

proptest! {
    #![proptest_config(config(5_000))]

    #[test]
    fn core_figures((t, h) in signal(), settled in wild_f64()) {
        use trackbelt::figures::{period_and_decrement, PeakTracker};
        let mut p = PeakTracker::new();
        for (&t, &h) in t.iter().zip(&h) {
            p.push(t, h);
        }
        let pd = period_and_decrement(p.maxima(), settled);
        if let Some((a, b)) = pd {
            prop_assert!(a.is_finite() && b.is_finite(), "{pd:?}");
        }
        let _ = p.minima();
    }
}

proptest! {
    #![proptest_config(config(3_000))]

    #[test]
    fn series_figures((t, h) in signal()) {
        let (a, b, c) = trackbelt_host::calibrate::series_figures(&t, &h);
        prop_assert!(finite_or_none(a) && finite_or_none(b) && finite_or_none(c), "{a:?} {b:?} {c:?}");
    }
}

proptest! {
    #![proptest_config(config(3_000))]

    #[test]
    fn diagnosis_signature((t, h) in signal(), settled in prop_oneof![3 => 250.0..350.0f64, 1 => wild_f64()],
                           min_amp in prop_oneof![3 => 0.0..10.0f64, 1 => wild_f64()]) {
        // Its contract: as many times as heights (the callers pass a
        // series' two columns). Unequal lengths: see the ignored test
        // `signature_unequal_lengths` at the end.
        let n = t.len().min(h.len());
        let s = trackbelt_host::diagnose_dynamic::signature(&t[..n], &h[..n], settled, min_amp);
        for c in &s.cycles {
            let _ = (c.time_s, c.amplitude_mm, c.period_s, c.log_decrement);
        }
    }
}

// ---------------------------------------------------------------------------
// Inputs found by the generated tests, kept as explicit regression cases
// ---------------------------------------------------------------------------

#[test]
fn found_belt_with_too_many_links_for_its_mass_is_an_error() {
    // link mass 2.2e-308 / 2^53 underflows to 0: was accepted.
    let belt = Belt {
        length_m: 624903.0949821813,
        width_m: 0.0016,
        thickness_m: 8e-5,
        mass_kg: 2.2250738585072014e-308,
        links: 9007199254740992,
    };
    assert!(Model::new(belt, law()).is_err());
}

#[test]
fn found_torque_table_with_overflowing_slope_is_an_error() {
    // slope -1e300 / 1e-15 = inf: was accepted, eval gave inf.
    assert!(TorqueTable::new(&[-1.0444334992350146e-15, 0.0], &[-1e300, 0.0]).is_err());
    // Found by the long campaign: finite slope 3.9e302, but the torque at
    // zero (f64::MIN + slope·463650) overflowed to inf.
    assert!(TorqueTable::new(&[-463650.06553777866], &[-1.7976931348623157e308]).is_err());
}

#[test]
fn found_all_nan_series_has_no_figures() {
    // series_figures gave Some(NaN) as the settled height.
    let t: Vec<f64> = (0..40).map(|i| i as f64 * 0.1).collect();
    let h = vec![f64::NAN; 40];
    assert_eq!(
        trackbelt_host::calibrate::series_figures(&t, &h),
        (None, None, None)
    );
}

#[test]
fn found_infinite_maxima_give_no_core_figures() {
    use trackbelt::figures::{period_and_decrement, Extremum};
    // (inf - 0) / (inf - 0) = NaN decrement: was Some((0.002, NaN)).
    let m = [
        Extremum {
            time_s: 0.0,
            value: f64::INFINITY,
        },
        Extremum {
            time_s: 0.002,
            value: f64::INFINITY,
        },
    ];
    assert_eq!(period_and_decrement(&m, 0.0), None);
    assert_eq!(period_and_decrement(&m[..1], 0.0), None);
}

/// Found: `signature` indexes past the end when `h` is longer than `t`
/// (`index out of bounds: the len is 4 but the index is 4`). Its callers
/// pass equal lengths; the fix belongs to host/src/diagnose_dynamic.rs
/// (another helper's file this round).
#[test]
fn signature_unequal_lengths() {
    let t = [f64::NAN; 4];
    let h = [
        f64::NAN,
        f64::NAN,
        f64::NAN,
        0.0,
        -1.3238434299905018e52,
        0.0,
    ];
    let _ = trackbelt_host::diagnose_dynamic::signature(&t, &h, 250.0, 0.0);
}

#[test]
fn found_vertex_of_samples_out_of_order_does_not_panic() {
    // t0 > t2: `clamp(d0, d2)` with min > max panicked (reached from the
    // host's series figures and the diagnosis signature).
    let e = trackbelt::figures::vertex([(2.5e299, 1.0), (0.0, 3.0), (-1.797693132368688e308, 2.0)]);
    assert_eq!((e.time_s, e.value), (0.0, 3.0));
    let e = trackbelt::figures::vertex([(1.0, 1.0), (0.5, 3.0), (0.0, 2.0)]);
    assert!(e.value.is_finite());
}

#[test]
fn found_series_path_outside_the_dataset_is_a_manifest_error() {
    // `series = "/"` was read as the file system's root ("/: cannot read
    // the series file: Is a directory"): an error naming neither the
    // manifest nor its line.
    use trackbelt_host::dataset::DatasetError;
    let sets = datasets();
    let (name, manifest, series) = &sets[2];
    for bad in ["/", "/etc/hostname", "../x.csv", "a/../../x.csv"] {
        let dir = TempDir::new(name);
        let text: String = manifest
            .lines()
            .map(|l| {
                if l.trim_start().starts_with("series") {
                    format!("series = {bad:?}")
                } else {
                    l.to_owned()
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        std::fs::write(dir.0.join("dataset.toml"), text).unwrap();
        for (f, b) in series {
            std::fs::write(dir.0.join(f), b).unwrap();
        }
        match trackbelt_host::dataset::load(&dir.0) {
            Err(DatasetError::Manifest { line: Some(_), .. }) => {}
            other => panic!("{bad}: {other:?}"),
        }
    }
}

// ---------------------------------------------------------------------------
// Running gear: its estimator table (temperature, tension), the belt-health
// monitor, the running-gear configuration and its rig
// ---------------------------------------------------------------------------

fn gear_table() -> &'static trackbelt::estimator::GearTable<f64> {
    use std::sync::OnceLock;
    static T: OnceLock<trackbelt::estimator::GearTable<f64>> = OnceLock::new();
    T.get_or_init(|| {
        trackbelt_host::firmware::gear_estimator_table(&repo_path(
            "firmware/params/gear-4wheel.toml",
        ))
        .unwrap()
        .table
    })
}

/// A speed/tick/temperature/tension sample: mostly plausible, often wild.
fn gear_sample() -> impl Strategy<Value = (f64, f64, Option<f64>, Option<f64>)> {
    (
        sample(),
        proptest::option::of(prop_oneof![4 => -20.0..90.0f64, 1 => wild_f64()]),
        proptest::option::of(prop_oneof![4 => 0.0..1500.0f64, 1 => wild_f64()]),
    )
        .prop_map(|((w, dt), temp, tension)| (w, dt, temp, tension))
}

fn run_gear_table<T: Real>(
    samples: &[(f64, f64, Option<f64>, Option<f64>)],
) -> Result<(), TestCaseError> {
    let table = gear_table().cast::<T>();
    let mut state = EstimatorState::<T>::new();
    for &(w, dt, temp, tension) in samples {
        let e = table.update(
            &mut state,
            T::from_f64(w),
            T::from_f64(dt),
            temp.map(T::from_f64),
            tension.map(T::from_f64),
        );
        prop_assert!(
            e.torque_nm.is_finite() && e.bending_nm.is_finite(),
            "not finite at {w} {dt} {temp:?} {tension:?}: {e:?}"
        );
        if !T::from_f64(w).is_finite() {
            prop_assert!(e.status.contains(Status::SPEED_NOT_FINITE));
        }
        let bad_input = |x: Option<f64>| x.is_some_and(|v| !T::from_f64(v).is_finite());
        if (bad_input(temp) || bad_input(tension)) && T::from_f64(w).is_finite() {
            prop_assert!(!e.status.is_ok(), "{temp:?} {tension:?}: {e:?}");
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(2_000))]

    #[test]
    fn gear_table_f32(s in proptest::collection::vec(gear_sample(), 1..48)) {
        run_gear_table::<f32>(&s)?;
    }
}

proptest! {
    #![proptest_config(config(2_000))]

    #[test]
    fn gear_table_fx(s in proptest::collection::vec(gear_sample(), 1..48)) {
        run_gear_table::<Fx>(&s)?;
    }
}

/// One monitor tick's input: speed, torque, tick, temperature, free-running.
type MonitorSample = (f64, f64, f64, Option<f64>, bool);

fn monitor_sample() -> impl Strategy<Value = MonitorSample> {
    (
        sample(),
        prop_oneof![4 => -5.0..5.0f64, 1 => wild_f64()],
        proptest::option::of(prop_oneof![4 => -20.0..90.0f64, 1 => wild_f64()]),
        prop_oneof![4 => Just(true), 1 => Just(false)],
    )
        .prop_map(|((w, dt), tau, temp, free)| (w, tau, dt, temp, free))
}

fn run_monitor<T: Real>(samples: &[MonitorSample]) -> Result<(), TestCaseError> {
    use trackbelt::monitor::{Monitor, MonitorConfig, MonitorInput, MonitorStatus};
    let table = table().cast::<T>();
    let config = MonitorConfig::<T>::default();
    prop_assert!(config.validate().is_ok());
    let mut m = Monitor::new(&config, &table);
    for &(w, tau, dt, temp, free) in samples {
        let input = MonitorInput {
            speed_rad_s: T::from_f64(w),
            torque_nm: T::from_f64(tau),
            dt_s: T::from_f64(dt),
            temperature_c: temp.map(T::from_f64),
            free_running: free,
        };
        let before = *m.state();
        let out = m.update(&input);
        for (name, x) in [
            ("loss_scale", out.loss_scale),
            ("loss_scale_sd", out.loss_scale_sd),
            ("bearing_nm", out.bearing_nm),
            ("bearing_sd", out.bearing_sd),
            ("health", out.health),
        ] {
            prop_assert!(x.is_finite(), "{name} not finite after {input:?}: {out:?}");
        }
        prop_assert!(out.loss_scale_sd >= T::ZERO && out.bearing_sd >= T::ZERO);
        let nonfinite = !(input.speed_rad_s.is_finite()
            && input.torque_nm.is_finite()
            && input.dt_s.is_finite()
            && input.temperature_c.is_none_or(|t| t.is_finite()));
        if nonfinite {
            prop_assert!(
                out.status.contains(MonitorStatus::BAD_INPUT),
                "{input:?}: {out:?}"
            );
        }
        if out.status.contains(MonitorStatus::BAD_INPUT) {
            prop_assert_eq!(&before, m.state(), "state changed on a bad tick");
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(2_000))]

    #[test]
    fn monitor_f32(s in proptest::collection::vec(monitor_sample(), 1..64)) {
        run_monitor::<f32>(&s)?;
    }
}

proptest! {
    #![proptest_config(config(2_000))]

    #[test]
    fn monitor_fx(s in proptest::collection::vec(monitor_sample(), 1..64)) {
        run_monitor::<Fx>(&s)?;
    }
}

fn wheel() -> impl Strategy<Value = trackbelt::gear::Wheel<f64>> {
    use trackbelt::gear::{Wheel, WheelRole};
    (
        prop_oneof![
            Just(WheelRole::Drive),
            Just(WheelRole::Idler),
            Just(WheelRole::Road),
            Just(WheelRole::Support)
        ],
        prop_oneof![4 => -1.0..1.0f64, 1 => wild_f64()],
        prop_oneof![4 => -0.3..0.3f64, 1 => wild_f64()],
        prop_oneof![4 => 0.02..0.4f64, 1 => wild_f64()],
    )
        .prop_map(|(role, x_m, y_m, diameter_m)| Wheel {
            role,
            x_m,
            y_m,
            diameter_m,
        })
}

proptest! {
    #![proptest_config(config(10_000))]

    /// Any list of wheels (up to 10: two past the capacity), tensioner and
    /// ground: `push` and `validate` return a value or a typed error.
    #[test]
    fn running_gear_config(wheels in proptest::collection::vec(wheel(), 0..10),
                           force in proptest::option::of(wild_f64()),
                           load in proptest::option::of(wild_f64()),
                           bearing in wild_f64()) {
        use trackbelt::gear::{Ground, RunningGear, Tensioner, MAX_WHEELS};
        let mut g = RunningGear::new(match force {
            Some(force_n) => Tensioner::Force { force_n },
            None => Tensioner::FixedCentre,
        });
        for (k, w) in wheels.iter().enumerate() {
            prop_assert_eq!(g.push(*w).is_ok(), k < MAX_WHEELS);
        }
        g.ground = load.map(|load_kg| Ground { load_kg });
        g.bearing_friction_nm = bearing;
        if g.validate().is_ok() {
            prop_assert!(g.drive().is_some() && g.idler().is_some());
            prop_assert!(g.wheels.iter().all(|w| w.diameter_m > 0.0 && w.x_m.is_finite()));
        }
    }
}

proptest! {
    #![proptest_config(config(12))]

    /// A plausible four-wheel robot with every dimension jittered: the belt
    /// settles on it or the rig returns a typed error (too short, too long,
    /// no convergence), never a panic or a hang.
    #[test]
    fn running_gear_on_the_rig(j in proptest::collection::vec(0.6..1.6f64, 8), load in 1.0..40.0f64) {
        use trackbelt::gear::{Ground, RunningGear, Tensioner, Wheel, WheelRole};
        use trackbelt::rig::Rig;
        let mut g = RunningGear::new(Tensioner::Force { force_n: 400.0 * j[0] });
        for (role, x, y, d) in [
            (WheelRole::Drive, 0.0, 0.0, 0.16 * j[1]),
            (WheelRole::Idler, 0.52 * j[2], 0.0, 0.14 * j[3]),
            (WheelRole::Road, 0.17 * j[4], -0.06 * j[5], 0.09),
            (WheelRole::Road, 0.35 * j[6], -0.06 * j[7], 0.09),
        ] {
            g.push(Wheel { role, x_m: x, y_m: y, diameter_m: d }).unwrap();
        }
        g.ground = Some(Ground { load_kg: load });
        if g.validate().is_ok() {
            let belt = Belt { length_m: 1.4, width_m: 0.1, thickness_m: 0.006, mass_kg: 2.5, links: 44 };
            let law = JointLaw::new(Stiffness::Constant { kz: 3.0 }, 0.15);
            if let Ok(law) = law {
                if let Ok(model) = Model::new(belt, law) {
                    if let Ok(rig) = Rig::<f64, { trackbelt_host::rig::RIG_CAPACITY }>::from_gear(model, &g, Settings::default()) {
                        prop_assert!(rig.drive_torque_nm().is_finite());
                    }
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(config(12))]

    /// The same robot with a fixed idler centre, jittered from 30 mm inside
    /// to 6 mm outside where the belt is tight round the wheels: the belt
    /// settles (pulling on the idler with at least its weight) or the rig
    /// returns a typed error, never a panic or a hang.
    #[test]
    fn running_gear_fixed_centre_on_the_rig(j in (0.85..1.1f64, 0.8..1.25f64, 0.9..1.3f64), dx in -0.03..0.006f64) {
        use trackbelt::gear::{Ground, RunningGear, Tensioner, Wheel, WheelRole};
        use trackbelt::rig::Rig;
        let wheels = |idler_x: f64| {
            let mut g = RunningGear::new(Tensioner::FixedCentre);
            for (role, x, y, d) in [
                (WheelRole::Drive, 0.0, 0.0, 0.16 * j.0),
                (WheelRole::Idler, idler_x, 0.0, 0.14 * j.1),
                (WheelRole::Road, 0.13, -0.07 * j.2, 0.10),
                (WheelRole::Road, 0.29, -0.07 * j.2, 0.10),
            ] {
                g.push(Wheel { role, x_m: x, y_m: y, diameter_m: d }).unwrap();
            }
            g.ground = Some(Ground { load_kg: 12.0 });
            g
        };
        let belt = Belt { length_m: 1.4, width_m: 0.1, thickness_m: 0.008, mass_kg: 2.5, links: 44 };
        let model = Model::new(belt, JointLaw::new(Stiffness::Constant { kz: 3.0 }, 0.15).unwrap()).unwrap();
        // Where the belt is tight: the force tensioner's lay-out, read off
        // the error of a centre far out.
        let far = wheels(0.60);
        prop_assert!(far.validate().is_ok());
        let tight_m = match Rig::<f64, { trackbelt_host::rig::RIG_CAPACITY }>::from_gear(model.clone(), &far, Settings::default()) {
            Err(trackbelt::Error::FixedCentreBelt { fits_at_mm, .. }) => fits_at_mm * 1e-3,
            other => return Err(TestCaseError::fail(format!("a centre 600 mm out must be too far: {:?}", other.map(|_| ())))),
        };
        let g = wheels(tight_m + dx);
        if g.validate().is_ok() {
            match Rig::<f64, { trackbelt_host::rig::RIG_CAPACITY }>::from_gear(model.clone(), &g, Settings::default()) {
                Ok(rig) => {
                    prop_assert!(rig.idler_force_n() >= 2.5 * 9.81 * 0.999);
                    prop_assert!(rig.drive_torque_nm().is_finite());
                }
                Err(trackbelt::Error::FixedCentreBelt { short_by_mm, .. }) => {
                    prop_assert!(short_by_mm.is_finite());
                }
                Err(e) => return Err(TestCaseError::fail(format!("{e}"))),
            }
        }
    }
}

/// Found by `monitor_f32` (its shrunk input): speed jumps between ticks,
/// one tick of 1e-21 s, zero measured torque. The inertia torque went whole
/// into the RLS step; the loss scale ran to 2e20 and its sd to inf in f32.
/// The a-priori error is now clipped to the torque range and the estimates
/// held to a physical range.
#[test]
fn found_monitor_speed_jumps_stay_finite() -> Result<(), TestCaseError> {
    let s: Vec<MonitorSample> = vec![
        (-7.772810232172991, 0.0, 0.01134019797251995, None, true),
        (-0.9507060740587472, 0.0, 0.001, None, true),
        (2.3976016431763623, 0.0, 0.001, None, true),
        (8.58825876180597, 0.0, 0.001, None, true),
        (2.294987720643941, 0.0, 0.001, None, true),
        (-7.748825839747462, 0.0, 0.001, None, true),
        (28.970006370601833, 0.0, 0.001, None, true),
        (-4.724298797759948, 0.0, 1e-21, None, true),
        (-2.56795681997174, 0.0, 0.001, None, true),
        (9.538936523844649, 0.0, 0.001, None, true),
        (13.98402625268601, 0.0, 0.001, None, true),
        (-6.670333227329022, 0.0, 0.001, None, true),
        (7.815134425895337, 0.0, 0.04679622334942867, None, true),
    ];
    run_monitor::<f32>(&s)
}

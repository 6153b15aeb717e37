//! Calibration into firmware: the onboard estimator's table built from a
//! params file and written out as Rust `static`s (read-only data: flash).
//!
//! `firmware/build.rs` calls [`estimator_table`] and [`table_consts`], so a
//! `trackbelt calibrate … --out FILE.toml` result reaches the firmware by
//! pointing `TRACKBELT_PARAMS` at the file; the host test
//! (`host-tests/tests/qemu.rs`) calls [`estimator_table`] to rebuild the
//! same table and replay the firmware's run bit for bit.

use std::fmt::Write as _;
use std::path::Path;

use trackbelt::estimator::{
    BuildOptions, EstimatorTable, GearTable, MAX_TEMPERATURES, MAX_TENSIONS, SPEED_POINTS,
};
use trackbelt::params::{Method, Variant};
use trackbelt::rig::RigConfig;
use trackbelt::{Fx, Real};

use crate::error::{Error, Result, ResultExt};
use crate::gear::{gear_table, TableAxes};
use crate::params_file::ParamsFile;
use crate::rig::RIG_CAPACITY;
use crate::sim::model_for;

/// The estimator table of one params file.
#[derive(Debug, Clone)]
pub struct FirmwareTable {
    /// The variant the params file names, or the one whose link count its
    /// `[belt]` has; `None` for a version 2 belt with another link count.
    pub variant: Option<Variant>,
    /// The belt's number of links.
    pub links: usize,
    /// Its method.
    pub method: Method,
    /// The table in full precision (the reference build).
    pub table: EstimatorTable<f64>,
}

impl FirmwareTable {
    /// The name the firmware logs for the belt: the variant's (`E56`), else
    /// `N` and the link count (`N44`, as `trackbelt simulate --links 44`).
    ///
    /// ```
    /// # use trackbelt_host::firmware::estimator_table;
    /// # use std::path::Path;
    /// let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../params/E56.toml");
    /// assert_eq!(estimator_table(&p)?.name(), "E56");
    /// # Ok::<(), trackbelt_host::Error>(())
    /// ```
    pub fn name(&self) -> String {
        match self.variant {
            Some(v) => v.name().to_string(),
            None => format!("N{}", self.links),
        }
    }
}

/// Build the estimator table for the params file at `path`, on the default
/// rig (300 mm wheels, idler pulled by 500 N) with the default build
/// options. The file must name its variant.
///
/// A version 2 file ([`crate::params_file::System`]) gives its belt (any
/// link count the rig's chain holds; the firmware logs
/// [`FirmwareTable::name`]) and, when it
/// has one, its running gear, which must be the two-wheel rig
/// ([`Error::NeedsGearSimulation`] otherwise). Version 1 files build as
/// before, bit for bit.
pub fn estimator_table(path: &Path) -> Result<FirmwareTable> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        action: "cannot read params file",
        path: path.to_path_buf(),
        source,
    })?;
    if let Ok(sys) = crate::params_file::parse_system(&text, path) {
        if sys.version >= 2 {
            return system_table(&sys);
        }
    }
    let (pf, law) = ParamsFile::parse(&text, path)?;
    let variant = pf.variant()?.ok_or_else(|| Error::ParamsFile {
        path: path.to_path_buf(),
        line: None,
        message: "add `variant = \"E38\"|\"E56\"|\"E76\"` (the firmware needs the link count)"
            .into(),
    })?;
    let method = pf.method()?;
    let model = model_for(variant.links(), law)?;
    let table = EstimatorTable::from_model::<RIG_CAPACITY>(
        &model,
        &RigConfig::default(),
        &BuildOptions::default(),
    )
    .context_with(|| format!("estimator table for {}", path.display()))?;
    Ok(FirmwareTable {
        variant: Some(variant),
        links: variant.links(),
        method,
        table,
    })
}

/// [`estimator_table`] of a version 2 system.
fn system_table(sys: &crate::params_file::System) -> Result<FirmwareTable> {
    let path = &sys.path;
    let n = sys.belt.links;
    let variant = Variant::ALL.into_iter().find(|v| v.links() == n);
    let config = match &sys.gear {
        None => RigConfig::default(),
        Some(g) => g
            .two_wheel_rig_config()
            .ok_or_else(|| Error::NeedsGearSimulation {
                path: path.clone(),
                wheels: g.wheels.len(),
            })?,
    };
    let model = trackbelt::params::Model::new(sys.belt, sys.law.clone())?;
    let table =
        EstimatorTable::from_model::<RIG_CAPACITY>(&model, &config, &BuildOptions::default())
            .context_with(|| format!("estimator table for {}", path.display()))?;
    Ok(FirmwareTable {
        variant,
        links: n,
        method: sys.method,
        table,
    })
}

/// FNV-1a over the raw bits of every coefficient of `table` in the number
/// type `T` (a fingerprint the firmware logs, so a host replay can check
/// it runs the same table). The derived fields (grid speeds, the bearing
/// friction's regularisation) follow from the coefficients and are not
/// hashed.
pub fn table_hash<T: Real>(table: &EstimatorTable<T>, bits: impl Fn(T) -> u64) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |x: T| {
        for b in bits(x).to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    };
    eat(table.speed_step_rad_s);
    eat(table.inv_speed_step);
    table.loss_nm.iter().for_each(|&x| eat(x));
    table.loss_slope_nm_s.iter().for_each(|&x| eat(x));
    eat(table.inertia_kg_m2);
    eat(table.bearing_friction_nm);
    h
}

/// Bits of an `f32` for [`table_hash`].
pub fn f32_bits(x: f32) -> u64 {
    x.to_bits() as u64
}

/// Bits of an [`Fx`] for [`table_hash`].
pub fn fx_bits(x: Fx) -> u64 {
    x.to_bits() as u64
}

fn table_const<T: Real>(
    out: &mut String,
    name: &str,
    ty: &str,
    table: &EstimatorTable<T>,
    lit: impl Fn(T) -> String,
) {
    let arr = |xs: &[T; SPEED_POINTS]| {
        let items: Vec<String> = xs.iter().map(|&x| lit(x)).collect();
        format!("[{}]", items.join(", "))
    };
    let _ = writeln!(
        out,
        "/// The estimator table in `{ty}` (a `static`: read-only data, in flash).\n\
         pub static {name}: EstimatorTable<{ty}> = EstimatorTable {{\n    \
         speed_step_rad_s: {},\n    inv_speed_step: {},\n    loss_nm: {},\n    loss_slope_nm_s: {},\n    \
         inertia_kg_m2: {},\n    bearing_friction_nm: {},\n    knots_rad_s: {},\n    \
         bearing_inv_eps_s_per_rad: {},\n}};",
        lit(table.speed_step_rad_s),
        lit(table.inv_speed_step),
        arr(&table.loss_nm),
        arr(&table.loss_slope_nm_s),
        lit(table.inertia_kg_m2),
        lit(table.bearing_friction_nm),
        arr(&table.knots_rad_s),
        lit(table.bearing_inv_eps_s_per_rad),
    );
}

/// Rust source defining the statics `TABLE_F32: EstimatorTable<f32>` and
/// `TABLE_FX: EstimatorTable<Fx>` (exact bit patterns, derived fields
/// included) and their fingerprints `TABLE_F32_HASH`, `TABLE_FX_HASH`. Expects
/// `EstimatorTable`, `Fx` and `trackbelt::real::FxRepr` in scope where it
/// is included.
pub fn table_consts(table: &EstimatorTable<f64>) -> String {
    let t32: EstimatorTable<f32> = table.cast();
    let tfx: EstimatorTable<Fx> = table.cast();
    let mut s = String::new();
    table_const(&mut s, "TABLE_F32", "f32", &t32, |x| {
        format!("f32::from_bits({:#010x})", x.to_bits())
    });
    table_const(&mut s, "TABLE_FX", "Fx", &tfx, |x| {
        format!("Fx(FxRepr::from_bits({}))", x.to_bits())
    });
    let _ = writeln!(
        s,
        "/// Fingerprint of [`TABLE_F32`].\npub const TABLE_F32_HASH: u64 = {:#018x};\n\
         /// Fingerprint of [`TABLE_FX`].\npub const TABLE_FX_HASH: u64 = {:#018x};",
        table_hash(&t32, f32_bits),
        table_hash(&tfx, fx_bits),
    );
    s
}

/// Belt temperatures of the firmware's running-gear table, °C (the
/// temperature input's axis; outside it the input is held at the edge and
/// flagged).
pub const GEAR_TEMPERATURES_C: [f64; 4] = [0.0, 20.0, 40.0, 60.0];

/// The running-gear estimator table of one params file (version 2, with
/// `[belt]` and `[running_gear]`).
#[derive(Debug, Clone)]
pub struct GearFirmwareTable {
    /// The system the file describes.
    pub system: crate::params_file::System,
    /// The table in full precision: speed × [`GEAR_TEMPERATURES_C`] × the
    /// gear's own tension (the firmware has a temperature input, no
    /// tension input).
    pub table: GearTable<f64>,
}

/// Build the running-gear table for the params file at `path` with the
/// default build options (sequential without the `parallel` feature, as
/// in the firmware's build script).
pub fn gear_estimator_table(path: &Path) -> Result<GearFirmwareTable> {
    let system = crate::params_file::load_system(path)?;
    let gear = system.gear.clone().ok_or_else(|| Error::ParamsFile {
        path: path.to_path_buf(),
        line: None,
        message: "add a [running_gear] (the running-gear firmware needs the wheels)".into(),
    })?;
    let model = trackbelt::params::Model::new(system.belt, system.law.clone())?;
    let reference_c = system
        .law
        .effects
        .thermal_softening
        .map_or(20.0, |t| t.reference_temp_c);
    let mut axes = TableAxes::nominal(&gear, reference_c);
    axes.temperatures_c = GEAR_TEMPERATURES_C.to_vec();
    let table = gear_table(&model, &gear, &axes, &BuildOptions::default())
        .context_with(|| format!("running-gear estimator table for {}", path.display()))?;
    Ok(GearFirmwareTable { system, table })
}

/// FNV-1a over the raw bits of every coefficient of a running-gear table
/// (its base table's, then the axes and the columns; derived fields and
/// reciprocals not hashed).
pub fn gear_table_hash<T: Real>(table: &GearTable<T>, bits: impl Fn(T) -> u64 + Copy) -> u64 {
    let mut h = table_hash(&table.base, bits);
    let mut eat = |x: u64| {
        for b in x.to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    };
    eat(table.temperatures as u64);
    eat(table.tensions as u64);
    table.temperature_c.iter().for_each(|&x| eat(bits(x)));
    table.tension_n.iter().for_each(|&x| eat(bits(x)));
    eat(bits(table.nominal_temperature_c));
    eat(bits(table.nominal_tension_n));
    for (a, b) in table.loss_nm.iter().zip(&table.loss_slope_nm_s) {
        for (c, d) in a.iter().zip(b) {
            c.iter().chain(d.iter()).for_each(|&x| eat(bits(x)));
        }
    }
    h
}

fn gear_table_const<T: Real>(
    out: &mut String,
    name: &str,
    ty: &str,
    t: &GearTable<T>,
    hash: u64,
    lit: impl Fn(T) -> String + Copy,
) {
    let arr = |xs: &[T]| {
        let items: Vec<String> = xs.iter().map(|&x| lit(x)).collect();
        format!("[{}]", items.join(", "))
    };
    let cube = |c: &[[[T; SPEED_POINTS]; MAX_TENSIONS]; MAX_TEMPERATURES]| {
        let planes: Vec<String> = c
            .iter()
            .map(|p| {
                let rows: Vec<String> = p.iter().map(|r| arr(r)).collect();
                format!("[{}]", rows.join(", "))
            })
            .collect();
        format!("[{}]", planes.join(",\n        "))
    };
    let base = format!("{name}_BASE");
    table_const(out, &base, ty, &t.base, lit);
    let _ = writeln!(
        out,
        "/// The running-gear table in `{ty}` (a `static`: read-only data, in flash).\n\
         pub static {name}: GearTable<{ty}> = GearTable {{\n    base: {base},\n    \
         temperatures: {},\n    tensions: {},\n    temperature_c: {},\n    inv_temperature_step: {},\n    \
         tension_n: {},\n    inv_tension_step: {},\n    nominal_temperature_c: {},\n    \
         nominal_tension_n: {},\n    loss_nm: {},\n    loss_slope_nm_s: {},\n}};\n\
         /// Fingerprint of [`{name}`].\npub const {name}_HASH: u64 = {hash:#018x};",
        t.temperatures,
        t.tensions,
        arr(&t.temperature_c),
        arr(&t.inv_temperature_step),
        arr(&t.tension_n),
        arr(&t.inv_tension_step),
        lit(t.nominal_temperature_c),
        lit(t.nominal_tension_n),
        cube(&t.loss_nm),
        cube(&t.loss_slope_nm_s),
    );
}

/// Rust source defining `GEAR_TABLE_F32: GearTable<f32>` and
/// `GEAR_TABLE_FX: GearTable<Fx>` (exact bit patterns, derived fields
/// included) and their fingerprints `GEAR_TABLE_F32_HASH`,
/// `GEAR_TABLE_FX_HASH`. Expects `GearTable`, `EstimatorTable`, `Fx` and
/// `trackbelt::real::FxRepr` in scope.
pub fn gear_table_consts(table: &GearTable<f64>) -> String {
    let t32: GearTable<f32> = table.cast();
    let tfx: GearTable<Fx> = table.cast();
    let mut s = String::new();
    gear_table_const(
        &mut s,
        "GEAR_TABLE_F32",
        "f32",
        &t32,
        gear_table_hash(&t32, f32_bits),
        |x| format!("f32::from_bits({:#010x})", x.to_bits()),
    );
    gear_table_const(
        &mut s,
        "GEAR_TABLE_FX",
        "Fx",
        &tfx,
        gear_table_hash(&tfx, fx_bits),
        |x| format!("Fx(FxRepr::from_bits({}))", x.to_bits()),
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn consts_carry_exact_bits() {
        let mut table = EstimatorTable::<f64>::from_coefficients(
            1.0,
            1.0,
            [0.0; SPEED_POINTS],
            [0.0; SPEED_POINTS],
            0.1,
            0.0,
        );
        table.loss_nm[3] = 0.123_456_789;
        let s = table_consts(&table);
        let bits32 = format!("{:#010x}", (0.123_456_789f64 as f32).to_bits());
        assert!(s.contains(&bits32), "{s}");
        let bitsfx = format!("{}", Fx::from_f64(0.123_456_789).to_bits());
        assert!(s.contains(&bitsfx), "{s}");
        let a = table_hash(&table.cast::<f32>(), f32_bits);
        table.loss_nm[3] = 0.123_456_8;
        assert_ne!(a, table_hash(&table.cast::<f32>(), f32_bits));
    }

    #[test]
    fn version_2_files_give_their_belt_and_rig() {
        use crate::params_file::{shipped_law, to_file};
        use trackbelt::gear::RunningGear;
        use trackbelt::params::Belt;
        let dir = std::env::temp_dir().join(format!("trackbelt-fw2-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let v1 = Path::new(env!("CARGO_MANIFEST_DIR")).join("../params/E56.toml");
        let law = shipped_law(Variant::E56).unwrap();
        let write = |name: &str, belt: &Belt<f64>, gear: Option<&RunningGear<f64>>| {
            let p = dir.join(name);
            let text = to_file(Some(Variant::E56), Some(belt), &law, gear)
                .to_toml()
                .unwrap();
            std::fs::write(&p, text).unwrap();
            p
        };
        // The Shredder belt on the paper's rig: the same table as version 1
        // (the law up to the degree round trip of the file).
        let a = estimator_table(&v1).unwrap().table;
        let same = estimator_table(&write("same.toml", &Belt::shredder(56), None)).unwrap();
        assert_eq!(same.variant, Some(Variant::E56));
        assert_eq!(same.name(), "E56");
        for (x, y) in a.loss_nm.iter().zip(&same.table.loss_nm) {
            assert!((x - y).abs() <= 1e-9 * x.abs().max(1e-12), "{x} {y}");
        }
        // Another belt and smaller wheels: another table.
        let belt = Belt {
            length_m: 1.9,
            width_m: 0.12,
            thickness_m: 0.006,
            mass_kg: 3.0,
            links: 56,
        };
        let cfg = RigConfig {
            drive_diameter_m: 0.2,
            idler_diameter_m: 0.2,
            ..RigConfig::default()
        };
        let two = RunningGear::paper_rig(&cfg, 0.6).unwrap();
        let t = estimator_table(&write("two.toml", &belt, Some(&two))).unwrap();
        assert!(t.table.loss_nm[5] != a.loss_nm[5]);
        // Any link count the rig holds (issue 12): logged as N44.
        let n44 = estimator_table(&write("n44.toml", &Belt { links: 44, ..belt }, None)).unwrap();
        assert_eq!(
            (n44.variant, n44.links, n44.name().as_str()),
            (None, 44, "N44")
        );
        assert!(n44.table.loss_nm[5] != t.table.loss_nm[5]);
        // A link count beyond the rig's chain is an error naming it.
        let e = estimator_table(&write("n200.toml", &Belt { links: 200, ..belt }, None));
        assert!(e.is_err(), "{e:?}");
        // Another running gear is an error.
        let mut four = two.clone();
        four.wheels[1].y_m = 0.05;
        let e = estimator_table(&write("tilted.toml", &belt, Some(&four)));
        assert!(matches!(e, Err(Error::NeedsGearSimulation { .. })), "{e:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn params_file_without_variant_is_refused() {
        let dir = std::env::temp_dir().join(format!("trackbelt-fw-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("novariant.toml");
        std::fs::write(
            &p,
            "method = \"I\"\n[stiffness]\nkz_nmm_per_rad = 12600\n[damping]\ncz_nmms_per_rad = 650\n",
        )
        .unwrap();
        let e = estimator_table(&p).unwrap_err().to_string();
        assert!(e.contains("variant"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

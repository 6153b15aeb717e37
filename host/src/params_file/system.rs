//! Params file version 2: the whole system (belt, joint law with its
//! effects, running gear) in one TOML file.
//!
//! ```toml
//! version = 2
//! variant = "E38"                 # optional: the preset the law was made from
//!
//! [belt]                          # optional: default the paper's Shredder belt
//! length_mm = 1500
//! width_mm = 120
//! thickness_mm = 6
//! mass_kg = 2.5
//! links = 44                      # any N in 3..=128, or instead:
//! # grouser_pitch_mm = 34         # links = round(length_mm / grouser_pitch_mm)
//!
//! [joint]
//! method = "III"                  # I | II | III
//! angles_deg = [-44, -29, -6, 0, 3, 13]     # method III (I: kz_nmm_per_rad;
//! torques_nmm = [-17000, -4200, -1600, 0, 970, 10100]  # II: kz_pos_/kz_neg_nmm_per_rad)
//! cz_nmms_per_rad = 430
//! [joint.effects.joint_friction]  # optional, any of the DATA.md joint effects
//! torque_nm = 0.02
//!
//! [running_gear]                  # optional
//! bearing_friction_nm = 0.0
//! [running_gear.tensioner]
//! force_n = 500                   # or: fixed_centre = true
//! [[running_gear.wheels]]
//! role = "drive"                  # drive | idler | road | support
//! x_mm = 0
//! y_mm = 0
//! diameter_mm = 300
//! [[running_gear.wheels]]
//! role = "idler"
//! x_mm = 740
//! y_mm = 0
//! diameter_mm = 300
//! # [running_gear.ground]  load_kg = 12     (with road wheels)
//! # [running_gear.contact] stiffness_n_per_m = …, damping_n_s_per_m = …,
//! #   drive_friction = …, slip_speed_m_s = …, idler_mass_kg = …,
//! #   idler_damping_n_s_per_m = …          (defaults: the paper rig's)
//! ```
//!
//! Every error names the file and, where it can, the line
//! ([`Error::ParamsFile`]); unknown keys are warnings
//! ([`System::warnings`], `FILE:LINE: unknown key …`), as in the dataset
//! reader.

use super::{DampingSection, ParamsFile, StiffnessSection};
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use trackbelt::effects::{
    DahlFriction, Effects, JointFriction, PayneSoftening, RateDamping, ThermalSoftening,
};
use trackbelt::gear::{Ground, RunningGear, Tensioner, Wheel, WheelContact, WheelRole};
use trackbelt::joint::JointLaw;
use trackbelt::params::{Belt, Method, Variant, MIN_LINKS};
use trackbelt::rig::RigConfig;
use trackbelt::stiffness::Stiffness;

/// The params-file version this module reads and writes.
pub const VERSION: i64 = 2;

/// Most links a belt may have: the reference chain's capacity
/// ([`trackbelt::ReferenceChain`] holds N + 4 unknowns in 132; the rig,
/// N + 5, stops at 127 with a capacity error).
pub const MAX_LINKS: usize = 128;

/// A whole system read from a params file (version 1 or 2).
#[derive(Debug, Clone, PartialEq)]
pub struct System {
    /// The file it was read from.
    pub path: PathBuf,
    /// 1 (joint law only) or 2.
    pub version: u32,
    /// The preset the file names (`variant = "E38"`), if any.
    pub variant: Option<Variant>,
    /// The joint law's method.
    pub method: Method,
    /// The belt: the file's `[belt]`, else the paper's Shredder belt with
    /// the named variant's links (38 when none is named; see
    /// [`System::belt_given`] and [`System::links_given`]).
    pub belt: Belt<f64>,
    /// Whether the file has a `[belt]`.
    pub belt_given: bool,
    /// Whether the file fixes the number of links (a `[belt]` or a
    /// `variant`).
    pub links_given: bool,
    /// The joint law, SI, with its effects.
    pub law: JointLaw<f64>,
    /// The running gear, if the file describes one.
    pub gear: Option<RunningGear<f64>>,
    /// Problems that did not stop the load (unknown keys), each as
    /// `"FILE:LINE: …"`.
    pub warnings: Vec<String>,
}

/// `[belt]` (mm, kg).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct BeltSection {
    /// Loop length, mm.
    pub length_mm: f64,
    /// Width, mm.
    pub width_mm: f64,
    /// Thickness, mm.
    pub thickness_mm: f64,
    /// Mass, kg.
    pub mass_kg: f64,
    /// Number of links N (3..=[`MAX_LINKS`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub links: Option<i64>,
    /// Grouser pitch, mm: without `links`, N = round(length / pitch)
    /// (halves away from zero).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grouser_pitch_mm: Option<f64>,
}

/// `[joint]`: the stiffness keys of version 1's `[stiffness]`, the damping
/// and the effects.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct JointSection {
    /// "I", "II" or "III".
    pub method: String,
    /// Method I stiffness, N·mm/rad.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kz_nmm_per_rad: Option<f64>,
    /// Method II stiffness for ζ > 0, N·mm/rad.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kz_pos_nmm_per_rad: Option<f64>,
    /// Method II stiffness for ζ < 0, N·mm/rad.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kz_neg_nmm_per_rad: Option<f64>,
    /// Method III breakpoint angles, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angles_deg: Option<Vec<f64>>,
    /// Method III breakpoint torques, N·mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torques_nmm: Option<Vec<f64>>,
    /// Linear angular damping cz, N·mm·s/rad.
    pub cz_nmms_per_rad: f64,
    /// Optional terms of the joint law (DATA.md identifiers).
    #[serde(default, skip_serializing_if = "EffectsSection::is_empty")]
    pub effects: EffectsSection,
}

/// `[joint.effects]`: one table per effect identifier of DATA.md (SI, as
/// the core's [`trackbelt::effects`]).
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct EffectsSection {
    /// `joint_friction`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint_friction: Option<JointFrictionSection>,
    /// `quadratic_damping`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quadratic_damping: Option<QuadraticDampingSection>,
    /// `amplitude_stiffness`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude_stiffness: Option<AmplitudeStiffnessSection>,
    /// `rate_dependent_damping`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_dependent_damping: Option<RateDampingSection>,
    /// `thermal_softening`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal_softening: Option<ThermalSofteningSection>,
    /// `joint_friction` as Dahl friction (pre-sliding; a law with a
    /// memory, [`trackbelt::memory`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dahl_friction: Option<DahlFrictionSection>,
    /// `amplitude_stiffness` as Payne softening with memory
    /// ([`trackbelt::memory`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub payne_softening: Option<PayneSofteningSection>,
}

/// `[joint.effects.dahl_friction]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct DahlFrictionSection {
    /// Sliding friction moment Mc per joint, N·m.
    pub torque_nm: f64,
    /// Pre-sliding angle ζs, rad.
    pub presliding_rad: f64,
}

/// `[joint.effects.payne_softening]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PayneSofteningSection {
    /// Relative change of the dynamic stiffness from small to large
    /// amplitude, in (−1, 1): positive softens, negative hardens (see
    /// `trackbelt::memory::PayneSoftening`).
    pub depth: f64,
    /// Amplitude of half the change, rad.
    pub amplitude_rad: f64,
    /// Time the amplitude is remembered, s.
    pub memory_s: f64,
    /// Time the mean angle follows the motion in, s.
    pub mean_s: f64,
}

impl JointSection {
    /// The stiffness keys as version 1's `[stiffness]`.
    pub fn stiffness(&self) -> StiffnessSection {
        StiffnessSection {
            kz_nmm_per_rad: self.kz_nmm_per_rad,
            kz_pos_nmm_per_rad: self.kz_pos_nmm_per_rad,
            kz_neg_nmm_per_rad: self.kz_neg_nmm_per_rad,
            angles_deg: self.angles_deg.clone(),
            torques_nmm: self.torques_nmm.clone(),
        }
    }
}

impl EffectsSection {
    /// No effect.
    pub fn is_empty(&self) -> bool {
        *self == EffectsSection::default()
    }
}

/// `[joint.effects.joint_friction]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct JointFrictionSection {
    /// Coulomb torque per joint, N·m.
    pub torque_nm: f64,
    /// Smoothing speed, rad/s (default 0.01).
    #[serde(default = "default_smoothing")]
    pub smoothing_rad_s: f64,
}

/// `[joint.effects.quadratic_damping]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct QuadraticDampingSection {
    /// c₂ of `−c₂·ζ̇·|ζ̇|`, N·m·s²/rad².
    pub c2_nms2_per_rad2: f64,
}

/// `[joint.effects.amplitude_stiffness]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct AmplitudeStiffnessSection {
    /// k₃ of `−k₃·ζ³`, N·m/rad³.
    pub k3_nm_per_rad3: f64,
}

/// `[joint.effects.rate_dependent_damping]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RateDampingSection {
    /// c of `−c·|ζ̇|^p·sign ζ̇`, N·m·(s/rad)^p.
    pub coefficient: f64,
    /// p, in (0, 3].
    pub exponent: f64,
    /// Smoothing speed, rad/s (default 0.01).
    #[serde(default = "default_smoothing")]
    pub smoothing_rad_s: f64,
}

/// `[joint.effects.thermal_softening]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ThermalSofteningSection {
    /// Relative loss of stiffness and damping per kelvin, 1/K.
    pub alpha_per_k: f64,
    /// Temperature of the baseline law, °C (default 20).
    #[serde(default = "default_reference_temp")]
    pub reference_temp_c: f64,
    /// Belt temperature, °C (default: the reference).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temp_c: Option<f64>,
}

fn default_smoothing() -> f64 {
    0.01
}

fn default_reference_temp() -> f64 {
    20.0
}

/// `[running_gear]` (mm, N, kg).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct GearSection {
    /// Constant resisting torque of all bearings at the drive axle, N·m
    /// (default 0).
    #[serde(default)]
    pub bearing_friction_nm: f64,
    /// `[running_gear.tensioner]`.
    pub tensioner: TensionerSection,
    /// `[[running_gear.wheels]]`, 2 to 8 of them.
    pub wheels: Vec<WheelSection>,
    /// `[running_gear.ground]`: flat ground under the road wheels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ground: Option<GroundSection>,
    /// `[running_gear.contact]`: the belt–wheel contact law (default: the
    /// paper rig's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact: Option<ContactSection>,
}

/// `[running_gear.tensioner]`: exactly one of the two.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct TensionerSection {
    /// Force on the idler's axle, away from the drive wheel, N.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force_n: Option<f64>,
    /// `true`: the idler's centre is fixed where it is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fixed_centre: Option<bool>,
}

/// One `[[running_gear.wheels]]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct WheelSection {
    /// "drive", "idler", "road" or "support".
    pub role: String,
    /// Centre, forward, mm.
    pub x_mm: f64,
    /// Centre, up, mm.
    pub y_mm: f64,
    /// Diameter, mm.
    pub diameter_mm: f64,
}

/// `[running_gear.ground]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct GroundSection {
    /// The robot's mass carried by this track, kg.
    pub load_kg: f64,
}

/// `[running_gear.contact]`: every key optional (SI).
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct ContactSection {
    /// Normal stiffness of the belt–wheel contact, N/m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness_n_per_m: Option<f64>,
    /// Normal damping of the belt–wheel contact, N·s/m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping_n_s_per_m: Option<f64>,
    /// Friction coefficient belt–drive wheel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drive_friction: Option<f64>,
    /// Slip speed of the regularised friction, m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slip_speed_m_s: Option<f64>,
    /// Mass moving with the idler's axle, kg.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub idler_mass_kg: Option<f64>,
    /// Viscous damping of the idler's slider, N·s/m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub idler_damping_n_s_per_m: Option<f64>,
}

/// The version 2 document.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct SystemFile {
    /// Always 2.
    pub version: i64,
    /// The preset the law was made from ("E38", …), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variant: Option<String>,
    /// `[belt]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub belt: Option<BeltSection>,
    /// `[joint]`.
    pub joint: JointSection,
    /// `[running_gear]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub running_gear: Option<GearSection>,
}

impl SystemFile {
    /// The TOML text.
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| Error::Params(e.to_string()))
    }
}

/// m → mm: the shortest of 15 significant digits when it reads back to
/// the same metres (so a belt read as `5.2 × 1e-3` is written `5.2`), else
/// the plain product.
fn mm(x_m: f64) -> f64 {
    let v = x_m * 1e3;
    match format!("{v:.14e}").parse::<f64>() {
        Ok(c) if c / 1e3 == x_m || c * 1e-3 == x_m => c,
        _ => v,
    }
}

/// Read a params file (version 1 or 2) as a [`System`].
pub fn load_system(path: &Path) -> Result<System> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        action: "cannot read params file",
        path: path.to_path_buf(),
        source,
    })?;
    parse_system(&text, path)
}

/// Parse the text of a params file (version 1 or 2); `path` names it in
/// errors and warnings.
pub fn parse_system(text: &str, path: &Path) -> Result<System> {
    let doc = Doc::new(path, text);
    match doc.version()? {
        1 => doc.v1(),
        _ => doc.v2(),
    }
}

/// The number of links a grouser pitch gives: `round(length / pitch)`,
/// halves away from zero (`None` unless finite and positive).
pub fn links_from_pitch(length_mm: f64, pitch_mm: f64) -> Option<i64> {
    let n = (length_mm / pitch_mm).round();
    (n.is_finite() && n > 0.0 && n < 1e9 && pitch_mm > 0.0).then_some(n as i64)
}

impl System {
    /// The version 2 document of this system (the belt is written only if
    /// [`System::belt_given`]).
    pub fn to_file(&self) -> SystemFile {
        to_file(
            self.variant,
            self.belt_given.then_some(&self.belt),
            &self.law,
            self.gear.as_ref(),
        )
    }

    /// The version 2 TOML text of this system.
    pub fn to_toml(&self) -> Result<String> {
        self.to_file().to_toml()
    }

    /// The two-wheel rig this system's running gear is, if it is one.
    pub fn rig_config(&self) -> Option<RigConfig<f64>> {
        self.gear.as_ref()?.two_wheel_rig_config()
    }
}

/// The method a stiffness is written with.
pub fn method_of(law: &JointLaw<f64>) -> Method {
    match law.stiffness {
        Stiffness::Constant { .. } => Method::I,
        Stiffness::Bivalent { .. } => Method::II,
        Stiffness::Table(_) => Method::III,
    }
}

/// A version 2 document for a belt (`None`: none written), a law and a
/// running gear.
pub fn to_file(
    variant: Option<Variant>,
    belt: Option<&Belt<f64>>,
    law: &JointLaw<f64>,
    gear: Option<&RunningGear<f64>>,
) -> SystemFile {
    let v1 = ParamsFile::from_law(variant, method_of(law), law);
    let e = &law.effects;
    SystemFile {
        version: VERSION,
        variant: v1.variant,
        belt: belt.map(|b| BeltSection {
            length_mm: mm(b.length_m),
            width_mm: mm(b.width_m),
            thickness_mm: mm(b.thickness_m),
            mass_kg: b.mass_kg,
            links: Some(b.links as i64),
            grouser_pitch_mm: None,
        }),
        joint: JointSection {
            method: v1.method,
            kz_nmm_per_rad: v1.stiffness.kz_nmm_per_rad,
            kz_pos_nmm_per_rad: v1.stiffness.kz_pos_nmm_per_rad,
            kz_neg_nmm_per_rad: v1.stiffness.kz_neg_nmm_per_rad,
            angles_deg: v1.stiffness.angles_deg,
            torques_nmm: v1.stiffness.torques_nmm,
            cz_nmms_per_rad: v1.damping.cz_nmms_per_rad,
            effects: EffectsSection {
                joint_friction: e.joint_friction.map(|f| JointFrictionSection {
                    torque_nm: f.torque_nm,
                    smoothing_rad_s: f.smoothing_rad_s,
                }),
                quadratic_damping: e
                    .quadratic_damping
                    .map(|c2_nms2_per_rad2| QuadraticDampingSection { c2_nms2_per_rad2 }),
                amplitude_stiffness: e
                    .amplitude_stiffness
                    .map(|k3_nm_per_rad3| AmplitudeStiffnessSection { k3_nm_per_rad3 }),
                rate_dependent_damping: e.rate_dependent_damping.map(|r| RateDampingSection {
                    coefficient: r.coefficient,
                    exponent: r.exponent,
                    smoothing_rad_s: r.smoothing_rad_s,
                }),
                thermal_softening: e.thermal_softening.map(|t| ThermalSofteningSection {
                    alpha_per_k: t.alpha_per_k,
                    reference_temp_c: t.reference_temp_c,
                    temp_c: Some(t.temp_c),
                }),
                dahl_friction: e.dahl_friction.map(|d| DahlFrictionSection {
                    torque_nm: d.torque_nm,
                    presliding_rad: d.presliding_rad,
                }),
                payne_softening: e.payne_softening.map(|p| PayneSofteningSection {
                    depth: p.depth,
                    amplitude_rad: p.amplitude_rad,
                    memory_s: p.memory_s,
                    mean_s: p.mean_s,
                }),
            },
        },
        running_gear: gear.map(gear_section),
    }
}

fn role_name(r: WheelRole) -> &'static str {
    match r {
        WheelRole::Drive => "drive",
        WheelRole::Idler => "idler",
        WheelRole::Road => "road",
        WheelRole::Support => "support",
    }
}

fn gear_section(g: &RunningGear<f64>) -> GearSection {
    let d = WheelContact::<f64>::default();
    let c = &g.contact;
    let differs = |a: f64, b: f64| (a != b).then_some(a);
    let contact = ContactSection {
        stiffness_n_per_m: differs(c.stiffness_n_per_m, d.stiffness_n_per_m),
        damping_n_s_per_m: differs(c.damping_n_s_per_m, d.damping_n_s_per_m),
        drive_friction: differs(c.drive_friction, d.drive_friction),
        slip_speed_m_s: differs(c.slip_speed_m_s, d.slip_speed_m_s),
        idler_mass_kg: differs(c.idler_mass_kg, d.idler_mass_kg),
        idler_damping_n_s_per_m: differs(c.idler_damping_n_s_per_m, d.idler_damping_n_s_per_m),
    };
    GearSection {
        bearing_friction_nm: g.bearing_friction_nm,
        tensioner: match g.tensioner {
            Tensioner::Force { force_n } => TensionerSection {
                force_n: Some(force_n),
                fixed_centre: None,
            },
            Tensioner::FixedCentre => TensionerSection {
                force_n: None,
                fixed_centre: Some(true),
            },
        },
        wheels: g
            .wheels
            .iter()
            .map(|w| WheelSection {
                role: role_name(w.role).into(),
                x_mm: mm(w.x_m),
                y_mm: mm(w.y_m),
                diameter_mm: mm(w.diameter_m),
            })
            .collect(),
        ground: g.ground.map(|gr| GroundSection {
            load_kg: gr.load_kg,
        }),
        contact: (contact != ContactSection::default()).then_some(contact),
    }
}

// ---------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------

/// One step of a key path: a key or an array index.
#[derive(Debug, Clone)]
enum Step {
    Key(String),
    Index(usize),
}

fn keys(path: &[&str]) -> Vec<Step> {
    path.iter().map(|k| Step::Key((*k).to_string())).collect()
}

/// The text being read, with the places of its keys (parsed on demand).
struct Doc<'a> {
    path: &'a Path,
    text: &'a str,
    keys: std::cell::OnceCell<Option<toml_edit::ImDocument<&'a str>>>,
}

impl<'a> Doc<'a> {
    fn new(path: &'a Path, text: &'a str) -> Self {
        Doc {
            path,
            text,
            keys: std::cell::OnceCell::new(),
        }
    }

    fn line_at(&self, offset: usize) -> usize {
        crate::error::line_of(self.text, offset.min(self.text.len()))
    }

    /// The line where the key at `steps` is written (for an array entry:
    /// its header).
    fn line(&self, steps: &[Step]) -> Option<usize> {
        let doc = self
            .keys
            .get_or_init(|| toml_edit::ImDocument::parse(self.text).ok())
            .as_ref()?;
        let (last, parents) = steps.split_last()?;
        let mut item = doc.as_item();
        for s in parents {
            item = match s {
                Step::Key(k) => item.get(k.as_str()),
                Step::Index(i) => item.get(*i),
            }?;
        }
        let span = match last {
            Step::Key(k) => item.as_table_like()?.key(k)?.span(),
            Step::Index(i) => match item {
                toml_edit::Item::ArrayOfTables(a) => a.get(*i)?.span(),
                _ => item.get(*i)?.span(),
            },
        }?;
        Some(self.line_at(span.start))
    }

    /// An error at the key `steps` (its line, when found).
    fn err(&self, steps: &[Step], message: impl Into<String>) -> Error {
        let line = self.line(steps);
        let message = message.into();
        Error::ParamsFile {
            path: self.path.to_path_buf(),
            line,
            message: match line {
                Some(l) => format!("line {l}: {message}"),
                None => message,
            },
        }
    }

    fn toml_err(&self, e: toml::de::Error) -> Error {
        Error::ParamsFile {
            path: self.path.to_path_buf(),
            line: e.span().map(|s| self.line_at(s.start)),
            message: e.to_string(),
        }
    }

    /// `version`: absent or 1 → 1; 2 → 2; anything else an error.
    fn version(&self) -> Result<i64> {
        #[derive(Deserialize)]
        struct Probe {
            version: Option<toml::Value>,
        }
        let probe: Probe = toml::from_str(self.text).map_err(|e| self.toml_err(e))?;
        match probe.version {
            None => Ok(1),
            Some(toml::Value::Integer(v)) if v == 1 || v == VERSION => Ok(v),
            Some(v) => Err(self.err(
                &keys(&["version"]),
                format!(
                    "version = {v} is not supported: this trackbelt reads params files of \
                     version 1 (no `version` key) and 2"
                ),
            )),
        }
    }

    /// Deserialize `T`, collecting unknown keys as warnings.
    fn read<T: serde::de::DeserializeOwned>(&self) -> Result<(T, Vec<String>)> {
        let mut unknown: Vec<Vec<Step>> = Vec::new();
        let v: T = serde_ignored::deserialize(toml::Deserializer::new(self.text), |p| {
            unknown.push(steps_of(&p));
        })
        .map_err(|e| self.toml_err(e))?;
        let mut w: Vec<(Option<usize>, String)> = unknown
            .iter()
            .map(|s| {
                let line = self.line(s);
                let place = match line {
                    Some(l) => format!("{}:{l}", self.path.display()),
                    None => self.path.display().to_string(),
                };
                (
                    line,
                    format!(
                        "{place}: unknown key `{}` ignored (params files do not define it; \
                         check its spelling)",
                        dotted(s)
                    ),
                )
            })
            .collect();
        w.sort_by_key(|(l, _)| *l);
        Ok((v, w.into_iter().map(|(_, m)| m).collect()))
    }

    fn v1(&self) -> Result<System> {
        let (pf, mut warnings): (ParamsFile, Vec<String>) = self.read()?;
        // `version = 1` is allowed (and not a key of the version 1 struct).
        warnings.retain(|w| !w.contains("unknown key `version`"));
        let law = pf.joint_law().map_err(|e| self.err(&[], e.to_string()))?;
        let method = pf
            .method()
            .map_err(|e| self.err(&keys(&["method"]), e.to_string()))?;
        let variant = pf
            .variant()
            .map_err(|e| self.err(&keys(&["variant"]), e.to_string()))?;
        Ok(System {
            path: self.path.to_path_buf(),
            version: 1,
            variant,
            method,
            belt: Belt::shredder(variant.map_or(38, Variant::links)),
            belt_given: false,
            links_given: variant.is_some(),
            law,
            gear: None,
            warnings,
        })
    }

    fn v2(&self) -> Result<System> {
        let (f, warnings): (SystemFile, _) = self.read()?;
        let variant = match &f.variant {
            None => None,
            Some(v) => Some(Variant::parse(v).ok_or_else(|| {
                self.err(
                    &keys(&["variant"]),
                    format!("variant = {v:?}: expected E38, E56 or E76"),
                )
            })?),
        };
        let belt = match &f.belt {
            Some(b) => Some(self.belt(b)?),
            None => None,
        };
        let method = Method::parse(&f.joint.method).ok_or_else(|| {
            self.err(
                &keys(&["joint", "method"]),
                format!("method = {:?}: expected I, II or III", f.joint.method),
            )
        })?;
        let law = self.law(&f.joint)?;
        let gear = match &f.running_gear {
            Some(g) => Some(self.gear(g)?),
            None => None,
        };
        let links_given = belt.is_some() || variant.is_some();
        Ok(System {
            path: self.path.to_path_buf(),
            version: 2,
            variant,
            method,
            belt_given: belt.is_some(),
            belt: belt.unwrap_or_else(|| Belt::shredder(variant.map_or(38, Variant::links))),
            links_given,
            law,
            gear,
            warnings,
        })
    }

    fn belt(&self, b: &BeltSection) -> Result<Belt<f64>> {
        let at = |k: &str| keys(&["belt", k]);
        for (k, v, zero_ok) in [
            ("length_mm", b.length_mm, false),
            ("width_mm", b.width_mm, true),
            ("thickness_mm", b.thickness_mm, false),
            ("mass_kg", b.mass_kg, false),
        ] {
            if !(v.is_finite() && (v > 0.0 || (zero_ok && v == 0.0))) {
                return Err(self.err(
                    &at(k),
                    format!(
                        "[belt] {k} = {v}: must be finite and {}",
                        if zero_ok { "not negative" } else { "positive" }
                    ),
                ));
            }
        }
        let derived = match b.grouser_pitch_mm {
            None => None,
            Some(p) => Some(links_from_pitch(b.length_mm, p).ok_or_else(|| {
                self.err(
                    &at("grouser_pitch_mm"),
                    format!("[belt] grouser_pitch_mm = {p}: must be finite and positive"),
                )
            })?),
        };
        let (n, key) = match (b.links, derived) {
            (Some(n), Some(d)) if n != d => {
                return Err(self.err(
                    &at("links"),
                    format!(
                        "[belt] links = {n} but grouser_pitch_mm gives {d} \
                         (round(length_mm / grouser_pitch_mm)); give one of them"
                    ),
                ))
            }
            (Some(n), _) => (n, "links"),
            (None, Some(d)) => (d, "grouser_pitch_mm"),
            (None, None) => {
                return Err(self.err(
                    &keys(&["belt"]),
                    "[belt] needs `links` (3 to 128) or `grouser_pitch_mm`",
                ))
            }
        };
        if n < MIN_LINKS as i64 || n > MAX_LINKS as i64 {
            return Err(self.err(
                &at(key),
                format!(
                    "[belt] {n} links: a belt has {MIN_LINKS} to {MAX_LINKS} links (the \
                     reference chain's capacity)"
                ),
            ));
        }
        let belt = Belt {
            length_m: b.length_mm / 1e3,
            width_m: b.width_mm / 1e3,
            thickness_m: b.thickness_mm / 1e3,
            mass_kg: b.mass_kg,
            links: n as usize,
        };
        belt.validate()
            .map_err(|e| self.err(&keys(&["belt"]), format!("[belt]: {e}")))?;
        Ok(belt)
    }

    fn law(&self, j: &JointSection) -> Result<JointLaw<f64>> {
        let pf = ParamsFile {
            variant: None,
            method: j.method.clone(),
            stiffness: j.stiffness(),
            damping: DampingSection {
                cz_nmms_per_rad: j.cz_nmms_per_rad,
            },
        };
        let mut law = pf
            .joint_law()
            .map_err(|e| self.err(&keys(&["joint"]), format!("[joint]: {e}")))?;
        let e = &j.effects;
        law.effects = Effects {
            joint_friction: e.joint_friction.as_ref().map(|f| JointFriction {
                torque_nm: f.torque_nm,
                smoothing_rad_s: f.smoothing_rad_s,
            }),
            quadratic_damping: e.quadratic_damping.as_ref().map(|q| q.c2_nms2_per_rad2),
            amplitude_stiffness: e.amplitude_stiffness.as_ref().map(|a| a.k3_nm_per_rad3),
            rate_dependent_damping: e.rate_dependent_damping.as_ref().map(|r| RateDamping {
                coefficient: r.coefficient,
                exponent: r.exponent,
                smoothing_rad_s: r.smoothing_rad_s,
            }),
            thermal_softening: e.thermal_softening.as_ref().map(|t| ThermalSoftening {
                alpha_per_k: t.alpha_per_k,
                reference_temp_c: t.reference_temp_c,
                temp_c: t.temp_c.unwrap_or(t.reference_temp_c),
            }),
            dahl_friction: e.dahl_friction.as_ref().map(|d| DahlFriction {
                torque_nm: d.torque_nm,
                presliding_rad: d.presliding_rad,
            }),
            payne_softening: e.payne_softening.as_ref().map(|p| PayneSoftening {
                depth: p.depth,
                amplitude_rad: p.amplitude_rad,
                memory_s: p.memory_s,
                mean_s: p.mean_s,
            }),
        };
        law.effects.validate().map_err(|err| {
            self.err(
                &keys(&["joint", "effects"]),
                format!("[joint.effects]: {err}"),
            )
        })?;
        Ok(law)
    }

    fn gear(&self, g: &GearSection) -> Result<RunningGear<f64>> {
        let t = &g.tensioner;
        let tensioner = match (t.force_n, t.fixed_centre) {
            (Some(force_n), None | Some(false)) => Tensioner::Force { force_n },
            (None, Some(true)) => Tensioner::FixedCentre,
            _ => {
                return Err(self.err(
                    &keys(&["running_gear", "tensioner"]),
                    "[running_gear.tensioner] needs exactly one of `force_n` (N) and \
                     `fixed_centre = true`",
                ))
            }
        };
        let mut gear = RunningGear::new(tensioner);
        gear.bearing_friction_nm = g.bearing_friction_nm;
        if let Some(c) = &g.contact {
            let k = &mut gear.contact;
            let set = |dst: &mut f64, v: Option<f64>| {
                if let Some(v) = v {
                    *dst = v;
                }
            };
            set(&mut k.stiffness_n_per_m, c.stiffness_n_per_m);
            set(&mut k.damping_n_s_per_m, c.damping_n_s_per_m);
            set(&mut k.drive_friction, c.drive_friction);
            set(&mut k.slip_speed_m_s, c.slip_speed_m_s);
            set(&mut k.idler_mass_kg, c.idler_mass_kg);
            set(&mut k.idler_damping_n_s_per_m, c.idler_damping_n_s_per_m);
        }
        gear.ground = g.ground.as_ref().map(|gr| Ground {
            load_kg: gr.load_kg,
        });
        for (i, w) in g.wheels.iter().enumerate() {
            let at = || {
                vec![
                    Step::Key("running_gear".into()),
                    Step::Key("wheels".into()),
                    Step::Index(i),
                ]
            };
            let role = match w.role.as_str() {
                "drive" => WheelRole::Drive,
                "idler" => WheelRole::Idler,
                "road" => WheelRole::Road,
                "support" => WheelRole::Support,
                r => {
                    return Err(self.err(
                        &at(),
                        format!(
                            "wheel {}: role = {r:?}: expected drive, idler, road or support",
                            i + 1
                        ),
                    ))
                }
            };
            if !(w.x_mm.is_finite() && w.y_mm.is_finite()) {
                return Err(self.err(
                    &at(),
                    format!("wheel {}: x_mm and y_mm must be finite", i + 1),
                ));
            }
            if !(w.diameter_mm.is_finite() && w.diameter_mm > 0.0) {
                return Err(self.err(
                    &at(),
                    format!(
                        "wheel {}: diameter_mm = {}: must be finite and positive",
                        i + 1,
                        w.diameter_mm
                    ),
                ));
            }
            gear.push(Wheel {
                role,
                x_m: w.x_mm / 1e3,
                y_m: w.y_mm / 1e3,
                diameter_m: w.diameter_mm / 1e3,
            })
            .map_err(|e| self.err(&at(), format!("wheel {}: {e}", i + 1)))?;
        }
        gear.validate()
            .map_err(|e| self.err(&keys(&["running_gear"]), format!("[running_gear]: {e}")))?;
        Ok(gear)
    }
}

/// The steps of a `serde_ignored` path.
fn steps_of(path: &serde_ignored::Path<'_>) -> Vec<Step> {
    fn walk(path: &serde_ignored::Path<'_>, steps: &mut Vec<Step>) {
        use serde_ignored::Path;
        match path {
            Path::Root => {}
            Path::Seq { parent, index } => {
                walk(parent, steps);
                steps.push(Step::Index(*index));
            }
            Path::Map { parent, key } => {
                walk(parent, steps);
                steps.push(Step::Key(key.clone()));
            }
            Path::Some { parent }
            | Path::NewtypeStruct { parent }
            | Path::NewtypeVariant { parent } => walk(parent, steps),
        }
    }
    let mut steps = Vec::new();
    walk(path, &mut steps);
    steps
}

/// `running_gear.wheels[2].size`.
fn dotted(steps: &[Step]) -> String {
    let mut s = String::new();
    for st in steps {
        match st {
            Step::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Step::Index(i) => s.push_str(&format!("[{}]", i + 1)),
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params_file::shipped_text;

    const ROBOT: &str = r#"
version = 2

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
"#;

    fn p() -> &'static Path {
        Path::new("/x/robot.toml")
    }

    #[test]
    fn version_1_files_load_unchanged() {
        for v in Variant::ALL {
            let text = shipped_text(v);
            let sys = parse_system(text, p()).unwrap();
            let (_, law) = ParamsFile::parse(text, p()).unwrap();
            assert_eq!(sys.version, 1);
            assert_eq!(sys.law, law);
            assert_eq!(sys.variant, Some(v));
            assert_eq!(sys.belt, Belt::shredder(v.links()));
            assert!(!sys.belt_given && sys.links_given && sys.gear.is_none());
            assert!(sys.warnings.is_empty(), "{:?}", sys.warnings);
        }
    }

    #[test]
    fn version_2_reads_the_whole_system_and_round_trips() {
        let sys = parse_system(ROBOT, p()).unwrap();
        assert_eq!(sys.version, 2);
        assert!(sys.warnings.is_empty(), "{:?}", sys.warnings);
        assert_eq!(sys.belt.links, 44);
        assert!((sys.belt.length_m - 1.5).abs() < 1e-12);
        assert!((sys.law.damping - 0.43).abs() < 1e-12);
        assert_eq!(
            sys.law.effects.joint_friction.unwrap().smoothing_rad_s,
            0.01
        );
        assert_eq!(sys.law.effects.thermal_softening.unwrap().temp_c, 20.0);
        let g = sys.gear.as_ref().unwrap();
        assert_eq!(g.wheels.len(), 4);
        assert_eq!(g.ground.unwrap().load_kg, 12.0);
        assert!(sys.rig_config().is_none());
        // Round trip through the writer.
        let text = sys.to_toml().unwrap();
        let back = parse_system(&text, p()).unwrap();
        assert_eq!(back.belt, sys.belt);
        assert_same_law(&back.law, &sys.law);
        assert_eq!(back.gear, sys.gear);
        assert!(back.warnings.is_empty());
        // The version 1 API reads the law of a version 2 file.
        let (pf, law) = ParamsFile::parse(ROBOT, p()).unwrap();
        assert_eq!(law, sys.law);
        assert_eq!(pf.method, "III");
    }

    /// Equal up to the degree–radian round trip of the table's angles.
    fn assert_same_law(a: &JointLaw<f64>, b: &JointLaw<f64>) {
        assert_eq!(a.damping, b.damping);
        assert_eq!(a.effects, b.effects);
        for z in [-0.9, -0.5, -0.2, -0.01, 0.0, 0.03, 0.1, 0.4] {
            let (x, y) = (a.stiffness.eval(z), b.stiffness.eval(z));
            assert!(
                (x.0 - y.0).abs() <= 1e-12 * (1.0 + y.0.abs()),
                "{z}: {x:?} {y:?}"
            );
            assert!(
                (x.1 - y.1).abs() <= 1e-9 * (1.0 + y.1.abs()),
                "{z}: {x:?} {y:?}"
            );
        }
    }

    #[test]
    fn two_wheel_gear_is_the_rig() {
        let cfg = RigConfig {
            drive_diameter_m: 0.25,
            idler_force_n: 300.0,
            ..RigConfig::default()
        };
        let gear = RunningGear::paper_rig(&cfg, 0.6).unwrap();
        let law = trackbelt::params::paper::joint_law(Variant::E56, Method::I).unwrap();
        let f = to_file(None, Some(&Belt::shredder(50)), &law, Some(&gear));
        let sys = parse_system(&toml::to_string(&f).unwrap(), p()).unwrap();
        assert_eq!(sys.rig_config(), Some(cfg));
        assert_eq!(sys.method, Method::I);
        assert_eq!(sys.belt.links, 50);
    }

    #[test]
    fn links_from_grouser_pitch_round_half_away() {
        assert_eq!(links_from_pitch(1500.0, 30.0), Some(50));
        assert_eq!(links_from_pitch(1500.0, 40.0), Some(38)); // 37.5 → 38
        assert_eq!(links_from_pitch(1500.0, 0.0), None);
        let text = ROBOT.replace("links = 44", "grouser_pitch_mm = 34");
        assert_eq!(parse_system(&text, p()).unwrap().belt.links, 44); // 44.1
        let text = ROBOT.replace("links = 44", "links = 40\ngrouser_pitch_mm = 34");
        let e = parse_system(&text, p()).unwrap_err().to_string();
        assert!(
            e.contains("robot.toml") && e.contains("line 9") && e.contains("44"),
            "{e}"
        );
    }

    #[test]
    fn errors_name_file_and_line() {
        let cases = [
            ("links = 44", "links = 200", "line 9", "128"),
            ("links = 44", "links = 2", "line 9", "3 to 128"),
            ("mass_kg = 2.5", "mass_kg = -1", "line 8", "mass_kg"),
            (
                "role = \"road\"",
                "role = \"wheel\"",
                "line 41",
                "expected drive",
            ),
            (
                "diameter_mm = 90",
                "diameter_mm = 0",
                "line 41",
                "diameter_mm",
            ),
            (
                "force_n = 400",
                "force_n = 400\nfixed_centre = true",
                "line 26",
                "exactly one",
            ),
            ("version = 2", "version = 3", "line 2", "not supported"),
            ("method = \"III\"", "method = \"IV\"", "line 12", "IV"),
            ("load_kg = 12", "load_kg = \"x\"", "line 54", "robot.toml"),
        ];
        for (from, to, line, what) in cases {
            let text = ROBOT.replacen(from, to, 1);
            let e = parse_system(&text, p()).unwrap_err().to_string();
            assert!(
                e.contains("robot.toml") && e.contains(line) && e.contains(what),
                "{from} → {to}: {e}"
            );
        }
        // No ground with road wheels: the core's check, at [running_gear].
        let text = ROBOT.replace("[running_gear.ground]\nload_kg = 12\n", "");
        let e = parse_system(&text, p()).unwrap_err().to_string();
        assert!(e.contains("ground") && e.contains("line 23"), "{e}");
    }

    #[test]
    fn unknown_keys_are_warnings_with_lines() {
        let text = ROBOT
            .replace("links = 44", "links = 44\ncolour = \"black\"")
            .replace("load_kg = 12", "load_kg = 12\nslope_deg = 3");
        let sys = parse_system(&text, p()).unwrap();
        assert_eq!(sys.warnings.len(), 2, "{:?}", sys.warnings);
        assert!(
            sys.warnings[0].contains("robot.toml:10") && sys.warnings[0].contains("belt.colour")
        );
        assert!(sys.warnings[1].contains("running_gear.ground.slope_deg"));
        let v1 = format!("version = 1\n{}", shipped_text(Variant::E38));
        assert!(parse_system(&v1, p()).unwrap().warnings.is_empty());
        let v1 = shipped_text(Variant::E38).replace("[damping]", "[damping]\nkz = 3");
        let w = parse_system(&v1, p()).unwrap().warnings;
        assert!(w.len() == 1 && w[0].contains("damping.kz"), "{w:?}");
    }
}

//! The params file: a joint law (method I, II or III) in TOML.
//!
//! ```toml
//! variant = "E38"              # optional: the variant the law was made for
//! method = "III"               # I | II | III
//! [stiffness]                  # exactly one of the three forms:
//! kz_nmm_per_rad = 8600        #   method I
//! # kz_pos_nmm_per_rad = 125000, kz_neg_nmm_per_rad = 8600   (method II)
//! # angles_deg = [-40, -20, -5, 0, 3], torques_nmm = [...]   (method III)
//! [damping]
//! cz_nmms_per_rad = 450
//! ```
//!
//! Units follow the paper (N·mm/rad, N·mm·s/rad, degrees); the library gets
//! SI values.

mod system;

pub use system::{
    links_from_pitch, load_system, method_of, parse_system, to_file, AmplitudeStiffnessSection,
    BeltSection, ContactSection, DahlFrictionSection, EffectsSection, GearSection, GroundSection,
    JointFrictionSection, JointSection, PayneSofteningSection, QuadraticDampingSection,
    RateDampingSection, System, SystemFile, TensionerSection, ThermalSofteningSection,
    WheelSection, MAX_LINKS, VERSION,
};

use crate::error::{line_of, Error, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;
use trackbelt::joint::JointLaw;
use trackbelt::params::{Method, Variant};
use trackbelt::stiffness::{Stiffness, TorqueTable};

/// The TOML document.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ParamsFile {
    /// Variant the law belongs to ("E38", …).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variant: Option<String>,
    /// "I", "II" or "III".
    pub method: String,
    /// Stiffness.
    pub stiffness: StiffnessSection,
    /// Damping.
    pub damping: DampingSection,
}

/// `[stiffness]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct StiffnessSection {
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
}

/// `[damping]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct DampingSection {
    /// Linear angular damping, N·mm·s/rad.
    pub cz_nmms_per_rad: f64,
}

impl ParamsFile {
    /// Read and validate a params file.
    pub fn load(path: &Path) -> Result<(ParamsFile, JointLaw<f64>)> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            action: "cannot read params file",
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Parse and validate the text of a params file; `path` names it in
    /// errors.
    ///
    /// A version 2 file (the whole system, [`parse_system`]) gives its joint
    /// law (with its effects) and a version 1 view of it.
    pub fn parse(text: &str, path: &Path) -> Result<(ParamsFile, JointLaw<f64>)> {
        if is_v2(text) {
            let sys = parse_system(text, path)?;
            let pf = ParamsFile::from_law(sys.variant, sys.method, &sys.law);
            return Ok((pf, sys.law));
        }
        let pf: ParamsFile = toml::from_str(text).map_err(|e| Error::ParamsFile {
            path: path.to_path_buf(),
            line: e.span().map(|s| line_of(text, s.start)),
            message: e.to_string(),
        })?;
        let law = pf.joint_law().map_err(|e| Error::ParamsFile {
            path: path.to_path_buf(),
            line: None,
            message: e.to_string(),
        })?;
        Ok((pf, law))
    }

    /// The method named in the file.
    pub fn method(&self) -> Result<Method> {
        Method::parse(&self.method).ok_or_else(|| {
            Error::Params(format!("method = {:?}: expected I, II or III", self.method))
        })
    }

    /// The variant named in the file, if any.
    pub fn variant(&self) -> Result<Option<Variant>> {
        match &self.variant {
            None => Ok(None),
            Some(v) => Variant::parse(v)
                .map(Some)
                .ok_or_else(|| Error::Params(format!("variant = {v:?}: expected E38, E56 or E76"))),
        }
    }

    /// The joint law in SI units.
    pub fn joint_law(&self) -> Result<JointLaw<f64>> {
        let s = &self.stiffness;
        let mm = 1e-3;
        let missing = |m: &str| Error::Params(m.to_string());
        let stiffness =
            match self.method()? {
                Method::I => Stiffness::Constant {
                    kz: s.kz_nmm_per_rad.ok_or_else(|| {
                        missing("[stiffness] kz_nmm_per_rad is required for method I")
                    })? * mm,
                },
                Method::II => Stiffness::Bivalent {
                    kz_pos: s.kz_pos_nmm_per_rad.ok_or_else(|| {
                        missing("[stiffness] kz_pos_nmm_per_rad is required for method II")
                    })? * mm,
                    kz_neg: s.kz_neg_nmm_per_rad.ok_or_else(|| {
                        missing("[stiffness] kz_neg_nmm_per_rad is required for method II")
                    })? * mm,
                },
                Method::III => {
                    let a = s.angles_deg.as_ref().ok_or_else(|| {
                        missing("[stiffness] angles_deg is required for method III")
                    })?;
                    let t = s.torques_nmm.as_ref().ok_or_else(|| {
                        missing("[stiffness] torques_nmm is required for method III")
                    })?;
                    let a: Vec<f64> = a.iter().map(|d| d.to_radians()).collect();
                    let t: Vec<f64> = t.iter().map(|x| x * mm).collect();
                    Stiffness::Table(TorqueTable::new(&a, &t)?)
                }
            };
        Ok(JointLaw::new(stiffness, self.damping.cz_nmms_per_rad * mm)?)
    }

    /// A params file describing `law`.
    pub fn from_law(variant: Option<Variant>, method: Method, law: &JointLaw<f64>) -> ParamsFile {
        let k = 1e3;
        let mut s = StiffnessSection::default();
        match &law.stiffness {
            Stiffness::Constant { kz } => s.kz_nmm_per_rad = Some(kz * k),
            Stiffness::Bivalent { kz_pos, kz_neg } => {
                s.kz_pos_nmm_per_rad = Some(kz_pos * k);
                s.kz_neg_nmm_per_rad = Some(kz_neg * k);
            }
            Stiffness::Table(t) => {
                s.angles_deg = Some(t.angles_rad().iter().map(|a| a.to_degrees()).collect());
                s.torques_nmm = Some(t.torques_nm().iter().map(|x| x * k).collect());
            }
        }
        ParamsFile {
            variant: variant.map(|v| v.name().to_string()),
            method: method.name().to_string(),
            stiffness: s,
            damping: DampingSection {
                cz_nmms_per_rad: law.damping * k,
            },
        }
    }
}

/// Whether `text` declares `version = 2` (or any version other than 1, so
/// that [`parse_system`] reports it).
fn is_v2(text: &str) -> bool {
    #[derive(Deserialize)]
    struct Probe {
        version: Option<toml::Value>,
    }
    match toml::from_str::<Probe>(text) {
        Ok(p) => !matches!(p.version, None | Some(toml::Value::Integer(1))),
        Err(_) => false,
    }
}

/// The shipped calibrated params files (Table 1 dataset), by variant.
pub fn shipped_text(variant: Variant) -> &'static str {
    match variant {
        Variant::E38 => include_str!("../../params/E38.toml"),
        Variant::E56 => include_str!("../../params/E56.toml"),
        Variant::E76 => include_str!("../../params/E76.toml"),
    }
}

/// The shipped calibrated method III law of a variant.
pub fn shipped_law(variant: Variant) -> Result<JointLaw<f64>> {
    let context = || format!("shipped params/{}.toml", variant.name());
    let pf: ParamsFile = toml::from_str(shipped_text(variant))
        .map_err(|e| Error::Params(e.to_string()).context(context()))?;
    pf.joint_law().map_err(|e| e.context(context()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_all_methods() {
        for m in [Method::I, Method::II] {
            let law = trackbelt::params::paper::joint_law(Variant::E56, m).unwrap();
            let pf = ParamsFile::from_law(Some(Variant::E56), m, &law);
            let text = toml::to_string(&pf).unwrap();
            let back: ParamsFile = toml::from_str(&text).unwrap();
            let l2 = back.joint_law().unwrap();
            assert!((l2.damping - law.damping).abs() < 1e-12);
        }
        let t = TorqueTable::new(&[-0.6, -0.1, 0.05], &[-9.0, -0.8, 0.9]).unwrap();
        let law = JointLaw::new(Stiffness::Table(t), 0.36).unwrap();
        let pf = ParamsFile::from_law(None, Method::III, &law);
        let back: ParamsFile = toml::from_str(&toml::to_string(&pf).unwrap()).unwrap();
        let (a, b) = (
            back.joint_law().unwrap().stiffness.eval(-0.3),
            law.stiffness.eval(-0.3),
        );
        assert!((a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-9);
    }

    #[test]
    fn missing_fields_are_named() {
        let pf: ParamsFile =
            toml::from_str("method = \"II\"\n[stiffness]\nkz_pos_nmm_per_rad = 1\n[damping]\ncz_nmms_per_rad = 1\n")
                .unwrap();
        assert!(pf
            .joint_law()
            .unwrap_err()
            .to_string()
            .contains("kz_neg_nmm_per_rad"));
        let bad: Result<ParamsFile, _> = toml::from_str("method = \"I\"\n");
        assert!(bad.is_err());
    }
}

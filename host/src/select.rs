//! Which system a command simulates: the presets (`--variant`, `--method`),
//! any number of links (`--links N`) and a params file (`--params FILE`,
//! version 1 or 2).
//!
//! Precedence:
//!
//! * **Links N**: `--links`, else the params file's (its `[belt]` links, or
//!   the variant it names), else `--variant`'s, else the command's default
//!   preset.
//! * **Belt**: the params file's `[belt]` (with N links), else the paper's
//!   Shredder belt with N links.
//! * **Joint law**: the params file's, else the preset's (`--variant`, else
//!   the default preset: the paper's law for methods I and II, the shipped
//!   calibrated table for III). A law made for M links is carried to N ≠ M
//!   links by the constant-EI rule ([`rescale_law`]); the selection then
//!   carries a note saying so.
//! * **Method**: `--method`, else the params file's.
//! * **Running gear**: the params file's `[running_gear]`, if any.
//!
//! A `--variant` that contradicts the params file (another method, another
//! link count) is an error, unless `--links` settles the link count.

use crate::error::{Error, Result};
use crate::params_file::{load_system, shipped_law, System, MAX_LINKS};
use std::path::Path;
use trackbelt::effects::RateDamping;
use trackbelt::gear::RunningGear;
use trackbelt::joint::JointLaw;
use trackbelt::params::{Belt, Method, Model, Variant, MIN_LINKS};
use trackbelt::rig::RigConfig;
use trackbelt::stiffness::{Stiffness, TorqueTable};

/// What the command line asked for.
#[derive(Debug, Clone, Copy, Default)]
pub struct Choice<'a> {
    /// `--variant` (E38, E56, E76), if given.
    pub variant: Option<&'a str>,
    /// `--method` (I, II, III), if given.
    pub method: Option<&'a str>,
    /// `--links N`, if given.
    pub links: Option<usize>,
    /// `--params FILE`, if given.
    pub params: Option<&'a Path>,
    /// The preset used when nothing else fixes the links or the law.
    pub default_variant: Option<Variant>,
}

/// The system a command runs.
#[derive(Debug, Clone)]
pub struct Selected {
    /// "E38", "E56", "E76" for a preset link count, else `N<links>`.
    pub label: String,
    /// The preset the law came from (`--variant`, the file's `variant`, or
    /// the default), if any.
    pub variant: Option<Variant>,
    /// The method.
    pub method: Method,
    /// Belt and joint law.
    pub model: Model<f64>,
    /// The running gear of the params file, if any.
    pub gear: Option<RunningGear<f64>>,
    /// Whether this is the paper's world: the Shredder belt, a preset link
    /// count, the preset's own law (no params file, no rescaling).
    pub paper_world: bool,
    /// Notes for stderr (a law carried to another link count).
    pub notes: Vec<String>,
    /// Warnings of the params file (unknown keys, `FILE:LINE: …`).
    pub warnings: Vec<String>,
    /// The params file as read, if one was given.
    pub system: Option<System>,
}

fn parse_variant(s: &str) -> Result<Variant> {
    Variant::parse(s).ok_or_else(|| {
        Error::InvalidArgument(format!(
            "--variant {s:?}: expected E38, E56 or E76 (other link counts: --links N)"
        ))
    })
}

/// Check `--links N`: 3 to [`MAX_LINKS`].
pub fn check_links(n: usize) -> Result<usize> {
    if (MIN_LINKS..=MAX_LINKS).contains(&n) {
        Ok(n)
    } else {
        Err(Error::InvalidArgument(format!(
            "--links {n}: a belt has {MIN_LINKS} to {MAX_LINKS} links (the reference chain's \
             capacity)"
        )))
    }
}

/// The preset law of `variant` and `method`: the paper's for methods I and
/// II, the shipped calibrated table for III.
pub fn preset_law(variant: Variant, method: Method) -> Result<JointLaw<f64>> {
    match trackbelt::params::paper::joint_law(variant, method) {
        Some(law) => Ok(law),
        None => shipped_law(variant),
    }
}

/// Carry a joint law made for `from` links to `to` links by the
/// constant-EI rule (the SPEC's, as the calibration's parametrisation):
/// the same bending moment at the same curvature, so joint angles scale by
/// `from/to` and every moment-per-angle coefficient by `r = to/from`:
/// stiffness and cz × r, a table's angles × 1/r (torques kept), the
/// effects' c₂ × r², k₃ × r³, the power-law coefficient × r^p; Coulomb
/// friction torques and thermal softening stay.
pub fn rescale_law(law: &JointLaw<f64>, from: usize, to: usize) -> Result<JointLaw<f64>> {
    if from == to {
        return Ok(law.clone());
    }
    let r = to as f64 / from as f64;
    let stiffness = match &law.stiffness {
        Stiffness::Constant { kz } => Stiffness::Constant { kz: kz * r },
        Stiffness::Bivalent { kz_pos, kz_neg } => Stiffness::Bivalent {
            kz_pos: kz_pos * r,
            kz_neg: kz_neg * r,
        },
        Stiffness::Table(t) => {
            let a: Vec<f64> = t.angles_rad().iter().map(|a| a / r).collect();
            Stiffness::Table(TorqueTable::new(&a, t.torques_nm())?)
        }
    };
    let mut out = JointLaw::new(stiffness, law.damping * r)?;
    let e = law.effects;
    out.effects = e;
    out.effects.quadratic_damping = e.quadratic_damping.map(|c| c * r * r);
    out.effects.amplitude_stiffness = e.amplitude_stiffness.map(|k| k * r * r * r);
    out.effects.rate_dependent_damping = e.rate_dependent_damping.map(|d| RateDamping {
        coefficient: d.coefficient * r.powf(d.exponent),
        ..d
    });
    out.validate()?;
    Ok(out)
}

/// Resolve a [`Choice`] into the system to simulate.
pub fn select(c: &Choice) -> Result<Selected> {
    let arg_variant = c.variant.map(parse_variant).transpose()?;
    let arg_method = match c.method {
        Some(m) => Some(Method::parse(m).ok_or_else(|| {
            Error::InvalidArgument(format!("--method {m:?}: expected I, II or III"))
        })?),
        None => None,
    };
    let links_arg = c.links.map(check_links).transpose()?;
    let mut notes = Vec::new();
    let Some(path) = c.params else {
        let variant = arg_variant.or(c.default_variant).ok_or_else(|| {
            Error::InvalidArgument("give --variant (E38, E56, E76), --links N or --params".into())
        })?;
        let method = arg_method.ok_or_else(|| {
            Error::InvalidArgument("give --method (I, II or III) or --params".into())
        })?;
        let n = links_arg.unwrap_or(variant.links());
        let mut law = preset_law(variant, method)?;
        if n != variant.links() {
            law = rescale_law(&law, variant.links(), n)?;
            notes.push(format!(
                "the {} method {} law carried to {n} links (constant EI)",
                variant.name(),
                method.name()
            ));
        }
        return Ok(Selected {
            label: crate::sim::variant_label(n),
            variant: Some(variant),
            method,
            model: Model::new(Belt::shredder(n), law)?,
            gear: None,
            paper_world: n == variant.links(),
            notes,
            warnings: Vec::new(),
            system: None,
        });
    };
    let sys = load_system(path)?;
    if let Some(m) = arg_method {
        if m != sys.method {
            return Err(Error::InvalidArgument(format!(
                "{} holds a method {} law but --method {} was given",
                path.display(),
                sys.method.name(),
                m.name()
            )));
        }
    }
    let file_links = sys.links_given.then_some(sys.belt.links);
    if let (Some(v), Some(fl), None) = (arg_variant, file_links, links_arg) {
        if v.links() != fl {
            let what = match (sys.belt_given, sys.variant) {
                (false, Some(fv)) => format!("was made for {}", fv.name()),
                _ => format!("describes a belt of {fl} links"),
            };
            return Err(Error::InvalidArgument(format!(
                "{} {what} but --variant {} was given (its angles and stiffnesses belong to \
                 {fl} links; drop --variant, or give --links N to carry the law to N links)",
                path.display(),
                v.name(),
            )));
        }
    }
    let n = links_arg
        .or(file_links)
        .or(arg_variant.map(Variant::links))
        .or(c.default_variant.map(Variant::links))
        .ok_or_else(|| {
            Error::InvalidArgument(format!(
                "{} names no belt and no variant: give --variant or --links N",
                path.display()
            ))
        })?;
    let mut law = sys.law.clone();
    if let Some(fl) = file_links {
        if fl != n {
            law = rescale_law(&law, fl, n)?;
            notes.push(format!(
                "{}: the law for {fl} links carried to {n} links (constant EI)",
                path.display()
            ));
        }
    }
    let belt = Belt {
        links: n,
        ..sys.belt
    };
    Ok(Selected {
        label: crate::sim::variant_label(n),
        variant: sys.variant.or(arg_variant),
        method: sys.method,
        model: Model::new(belt, law)?,
        gear: sys.gear.clone(),
        paper_world: false,
        notes,
        warnings: sys.warnings.clone(),
        system: Some(sys),
    })
}

impl Selected {
    /// The rig this selection runs on: the params file's two-wheel running
    /// gear, else the paper's rig; `idler_force_n` (given on the command
    /// line) overrides the tensioner force. Any other running gear is
    /// [`Error::NeedsGearSimulation`].
    pub fn rig_config(&self, idler_force_n: Option<f64>) -> Result<RigConfig<f64>> {
        let mut config = match &self.gear {
            None => RigConfig::default(),
            Some(g) => g
                .two_wheel_rig_config()
                .ok_or_else(|| Error::NeedsGearSimulation {
                    path: self
                        .system
                        .as_ref()
                        .map(|s| s.path.clone())
                        .unwrap_or_default(),
                    wheels: g.wheels.len(),
                })?,
        };
        if let Some(f) = idler_force_n {
            config.idler_force_n = f;
        }
        config.validate()?;
        Ok(config)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_the_paper() {
        let s = select(&Choice {
            variant: Some("E56"),
            method: Some("I"),
            ..Choice::default()
        })
        .unwrap();
        assert_eq!(s.label, "E56");
        assert!(s.paper_world);
        assert_eq!(s.model, Model::paper(Variant::E56, Method::I).unwrap());
        assert_eq!(s.rig_config(None).unwrap(), RigConfig::default());
    }

    #[test]
    fn links_override_and_rescale() {
        let s = select(&Choice {
            variant: Some("E38"),
            method: Some("I"),
            links: Some(44),
            ..Choice::default()
        })
        .unwrap();
        assert_eq!(s.label, "N44");
        assert_eq!(s.model.belt.links, 44);
        assert!(!s.paper_world);
        let Stiffness::Constant { kz } = s.model.joint.stiffness else {
            panic!()
        };
        assert!((kz - 8.6 * 44.0 / 38.0).abs() < 1e-12);
        assert!(check_links(129).is_err() && check_links(2).is_err());
        // A table: the same torque at the scaled angle.
        let law = shipped_law(Variant::E38).unwrap();
        let r = rescale_law(&law, 38, 76).unwrap();
        let (a, b) = (law.stiffness.eval(-0.4).0, r.stiffness.eval(-0.2).0);
        assert!((a - b).abs() < 1e-12);
        assert!((r.damping - 2.0 * law.damping).abs() < 1e-15);
    }

    #[test]
    fn params_file_conflicts_are_errors() {
        let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../params/E38.toml");
        let ok = select(&Choice {
            method: Some("III"),
            params: Some(&p),
            ..Choice::default()
        })
        .unwrap();
        assert_eq!(ok.label, "E38");
        assert_eq!(ok.model.joint, shipped_law(Variant::E38).unwrap());
        let bad = select(&Choice {
            variant: Some("E56"),
            params: Some(&p),
            ..Choice::default()
        });
        assert!(bad.unwrap_err().to_string().contains("E38"));
        let bad = select(&Choice {
            method: Some("I"),
            params: Some(&p),
            ..Choice::default()
        });
        assert!(bad.unwrap_err().to_string().contains("method III"));
        // --links settles the conflict.
        let s = select(&Choice {
            variant: Some("E56"),
            links: Some(56),
            params: Some(&p),
            ..Choice::default()
        })
        .unwrap();
        assert_eq!(s.model.belt.links, 56);
    }
}

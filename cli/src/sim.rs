//! Running the bench tests for the CLI: the JSON contract of
//! `trackbelt simulate` and the traces the plots draw.

use serde::Serialize;
use std::time::Instant;
use trackbelt::bench::{self, DynamicTest};
use trackbelt::params::{Method, Model, Variant};
use trackbelt::stiffness::JointLaw;
use trackbelt::{Chain, ReferenceChain, Settings};

/// Figures of one simulation, as `simulate --json` prints them (mm, s, deg).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SimOutput {
    /// "E38", "E56", "E76" (or "N<links>" for other link counts).
    pub variant: String,
    /// "I", "II", "III".
    pub method: String,
    /// Static height at A, mm.
    pub hs_mm: f64,
    /// Static width, mm.
    pub ws_mm: f64,
    /// Loaded settled height, mm.
    pub hd_mm: Option<f64>,
    /// Loaded settled width, mm.
    pub wd_mm: Option<f64>,
    /// Period of A, s.
    pub period_s: Option<f64>,
    /// Logarithmic decrement.
    pub log_decrement: Option<f64>,
    /// Joint-angle range at A over the dynamic test, degrees.
    pub angle_a_deg: Option<[f64; 2]>,
    /// Joint-angle range at C, degrees.
    pub angle_c_deg: Option<[f64; 2]>,
    /// Wall-clock time of the simulation work, s.
    pub wall_s: f64,
}

/// What the plots need.
#[derive(Debug, Clone, Default)]
pub struct SimTrace {
    /// (t s, A height mm) over the dynamic test.
    pub a_height: Vec<(f64, f64)>,
    /// Outer surface at the joints after the static test, mm.
    pub static_shape: Vec<(f64, f64)>,
    /// Outer surface at the joints, loaded and settled, mm.
    pub loaded_shape: Vec<(f64, f64)>,
}

/// Which tests to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tests {
    /// Static only.
    Static,
    /// Static then dynamic.
    Both,
}

fn shape<const D: usize>(c: &Chain<f64, D>) -> Vec<(f64, f64)> {
    let mut v: Vec<(f64, f64)> = (0..=c.links())
        .map(|j| {
            let p = c.outer_point_at_joint_m(j);
            (p.0 * 1e3, p.1 * 1e3)
        })
        .collect();
    if let Some(&first) = v.first() {
        v.push(first);
    }
    v
}

/// Label of a variant by link count.
pub fn variant_label(links: usize) -> String {
    match Variant::ALL.iter().find(|v| v.links() == links) {
        Some(v) => v.name().to_string(),
        None => format!("N{links}"),
    }
}

/// Build the model for a variant and a joint law.
pub fn model_for(links: usize, law: JointLaw<f64>) -> Result<Model<f64>, trackbelt::Error> {
    Model::new(trackbelt::params::Belt::shredder(links), law)
}

/// Run the static (and dynamic) test on `model`.
pub fn simulate(
    model: Model<f64>,
    method: Method,
    tests: Tests,
    settings: Settings<f64>,
    dynamic: DynamicTest<f64>,
) -> Result<(SimOutput, SimTrace), trackbelt::Error> {
    let links = model.belt.links;
    let mut chain = Box::new(ReferenceChain::new(model, settings)?);
    let t0 = Instant::now();
    let st = bench::static_test(&mut *chain)?;
    let mut trace = SimTrace {
        static_shape: shape(&chain),
        ..Default::default()
    };
    let mut out = SimOutput {
        variant: variant_label(links),
        method: method.name().to_string(),
        hs_mm: st.hs_mm,
        ws_mm: st.ws_mm,
        hd_mm: None,
        wd_mm: None,
        period_s: None,
        log_decrement: None,
        angle_a_deg: None,
        angle_c_deg: None,
        wall_s: 0.0,
    };
    if tests == Tests::Both {
        let mut h = Vec::with_capacity(4096);
        let d = bench::dynamic_test(&mut *chain, &dynamic, |c| {
            h.push((c.time_s(), c.a_height_m() * 1e3))
        })?;
        trace.a_height = h;
        trace.loaded_shape = shape(&chain);
        out.hd_mm = Some(d.hd_mm);
        out.wd_mm = Some(d.wd_mm);
        out.period_s = d.period_s;
        out.log_decrement = d.log_decrement;
        out.angle_a_deg = Some(d.angle_a_deg);
        out.angle_c_deg = Some(d.angle_c_deg);
    }
    out.wall_s = t0.elapsed().as_secs_f64();
    Ok((out, trace))
}

//! Running the bench tests for the CLI: the JSON contract of
//! `trackbelt simulate` and the traces the plots draw.

use serde::Serialize;
use std::time::Instant;
use trackbelt::bench::{self, BenchChain, DynamicTest};
use trackbelt::joint::JointLaw;
use trackbelt::params::{Method, Model, Variant};
use trackbelt::{Bushing, Chain, ReferenceBushingChain, ReferenceChain, Settings};

use crate::error::{Error, Result};
use crate::validity::{BenchValidity, Monitor};

/// How consecutive links are joined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Joint {
    /// Exact pins (inextensible chain): the default, far cheaper.
    #[default]
    Pin,
    /// The paper's literal bushing (eqs. 1–3: 1e8 N/m, 1e6 N·s/m).
    Bushing,
}

impl Joint {
    /// "pin" or "bushing".
    pub fn name(self) -> &'static str {
        match self {
            Joint::Pin => "pin",
            Joint::Bushing => "bushing",
        }
    }
}

/// Figures of one simulation, as `simulate --json` prints them (mm, s, deg).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SimOutput {
    /// "E38", "E56", "E76" (or `N<links>` for other link counts).
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
    /// "pin" or "bushing".
    pub joint: String,
    /// Bushing model only: the largest joint stretch, µm, over the run
    /// (static settle, dynamic test and the loaded settle).
    pub max_stretch_um: Option<f64>,
    /// Validity checks the run passed only in part, `"<check>: <value>"`
    /// (see [`crate::validity`]); absent from the JSON when there is none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
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
    /// What the validity checks measured.
    pub validity: BenchValidity,
}

/// Which tests to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tests {
    /// Static only.
    Static,
    /// Static then dynamic.
    Both,
}

fn closed(mut v: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    if let Some(&first) = v.first() {
        v.push(first);
    }
    v
}

/// Outer surface at the joints, mm, closed.
fn shape_of(links: usize, point: impl Fn(usize) -> (f64, f64)) -> Vec<(f64, f64)> {
    closed(
        (0..=links)
            .map(|j| {
                let p = point(j);
                (p.0 * 1e3, p.1 * 1e3)
            })
            .collect(),
    )
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

/// Run the static (and dynamic) test on `model` with pin joints.
pub fn simulate(
    model: Model<f64>,
    method: Method,
    tests: Tests,
    settings: Settings<f64>,
    dynamic: DynamicTest<f64>,
) -> Result<(SimOutput, SimTrace)> {
    simulate_joint(model, method, Joint::Pin, tests, settings, dynamic)
}

/// Run the static (and dynamic) test on `model` with the given joints.
///
/// The bushing chain is large (about 1.3 MB): it runs on its own thread
/// with a big stack.
pub fn simulate_joint(
    model: Model<f64>,
    method: Method,
    joint: Joint,
    tests: Tests,
    settings: Settings<f64>,
    dynamic: DynamicTest<f64>,
) -> Result<(SimOutput, SimTrace)> {
    let links = model.belt.links;
    match joint {
        Joint::Pin => with_sized_chain(
            model,
            settings,
            PinTests {
                links,
                method,
                tests,
                dynamic,
            },
        ),
        Joint::Bushing => std::thread::Builder::new()
            .stack_size(BUSHING_STACK_BYTES)
            .spawn(move || {
                let mut chain = Box::new(ReferenceBushingChain::new(
                    model,
                    Bushing::paper(),
                    settings,
                )?);
                let mut out = run_tests(
                    &mut *chain,
                    links,
                    method,
                    tests,
                    dynamic,
                    |c| shape_of(links, |j| c.outer_point_at_joint_m(j)),
                    |c| Some(c.max_stretch_m()),
                )?;
                out.0.joint = Joint::Bushing.name().to_string();
                Ok(out)
            })
            .map_err(|_| Error::Thread("could not start the bushing simulation thread"))?
            .join()
            .unwrap_or(Err(Error::Thread("the bushing simulation thread failed"))),
    }
}

/// Capacity of the pin-joint chain for belts of up to 44 links (E38).
const SMALL_CHAIN: usize = 48;
/// Capacity of the pin-joint chain for belts of 45 to 76 links (E56, E76);
/// longer belts run in the [`ReferenceChain`].
const MID_CHAIN: usize = 80;

/// A run on a pin-joint chain of any capacity ([`with_sized_chain`]).
pub(crate) trait ChainRun {
    /// What the run gives.
    type Output;
    /// Run on `chain`.
    fn run<const D: usize>(self, chain: &mut Chain<f64, D>) -> Result<Self::Output>;
}

/// Build `model`'s pin-joint chain in the smallest of three capacities
/// that holds it (48, 80, the [`ReferenceChain`]'s) and run `job` on it.
/// The arithmetic is the same in each (the loops run over the links, not
/// the capacity): a smaller one spares the zeroing and the cache of the
/// unused rows, and a calibration or a diagnosis simulates hundreds of
/// times.
pub(crate) fn with_sized_chain<R: ChainRun>(
    model: Model<f64>,
    settings: Settings<f64>,
    job: R,
) -> Result<R::Output> {
    let links = model.belt.links;
    if links + 4 <= SMALL_CHAIN {
        job.run(&mut *Box::new(Chain::<f64, SMALL_CHAIN>::new(
            model, settings,
        )?))
    } else if links + 4 <= MID_CHAIN {
        job.run(&mut *Box::new(Chain::<f64, MID_CHAIN>::new(
            model, settings,
        )?))
    } else {
        job.run(&mut *Box::new(ReferenceChain::new(model, settings)?))
    }
}

/// [`simulate_joint`]'s pin-joint run.
struct PinTests {
    links: usize,
    method: Method,
    tests: Tests,
    dynamic: DynamicTest<f64>,
}

impl ChainRun for PinTests {
    type Output = (SimOutput, SimTrace);
    fn run<const D: usize>(self, chain: &mut Chain<f64, D>) -> Result<Self::Output> {
        let links = self.links;
        run_tests(
            chain,
            links,
            self.method,
            self.tests,
            self.dynamic,
            |c| shape_of(links, |j| c.outer_point_at_joint_m(j)),
            |_| None,
        )
    }
}

fn max_opt(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.max(y)),
        (x, None) => x,
        (None, y) => y,
    }
}

/// Stack of the thread that runs the bushing chain.
const BUSHING_STACK_BYTES: usize = 64 << 20;

fn run_tests<const D: usize, C: BenchChain<f64, D>>(
    chain: &mut C,
    links: usize,
    method: Method,
    tests: Tests,
    dynamic: DynamicTest<f64>,
    shape: impl Fn(&C) -> Vec<(f64, f64)>,
    stretch: impl Fn(&C) -> Option<f64>,
) -> Result<(SimOutput, SimTrace)> {
    let t0 = Instant::now();
    let mut monitor = Monitor::new();
    let st = bench::static_test(chain)?;
    monitor.after_static(chain);
    let mut max_stretch = stretch(chain);
    let mut trace = SimTrace {
        static_shape: shape(chain),
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
        joint: Joint::Pin.name().to_string(),
        max_stretch_um: None,
        warnings: Vec::new(),
    };
    if tests == Tests::Both {
        let mut h = Vec::with_capacity(4096);
        let d = bench::dynamic_test(chain, &dynamic, |c| {
            h.push((c.time_s(), c.a_height_m() * 1e3));
            max_stretch = max_opt(max_stretch, stretch(c));
            monitor.observe(c);
        })?;
        monitor.after_dynamic(chain, &d);
        max_stretch = max_opt(max_stretch, stretch(chain));
        trace.a_height = h;
        trace.loaded_shape = shape(chain);
        out.hd_mm = Some(d.hd_mm);
        out.wd_mm = Some(d.wd_mm);
        out.period_s = d.period_s;
        out.log_decrement = d.log_decrement;
        out.angle_a_deg = Some(d.angle_a_deg);
        out.angle_c_deg = Some(d.angle_c_deg);
    }
    out.max_stretch_um = max_stretch.map(|m| m * 1e6);
    out.wall_s = t0.elapsed().as_secs_f64();
    trace.validity = monitor.validity();
    out.warnings = trace.validity.check()?;
    Ok((out, trace))
}

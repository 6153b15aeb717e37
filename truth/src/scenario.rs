//! What one dataset is made of, and how it is drawn at random.

use crate::law::{BendingLaw, DampingLaw, FrictionLaw, Material, Payne, Thermal};
use crate::rng::Rng;
use crate::Error;

/// The two kinds of series in `DATA.md`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SeriesKind {
    /// A roller drop test on a settled ring (`[[dynamic]]`).
    Dynamic,
    /// The belt turned between two wheels (`[[scroll]]`).
    Scroll,
}

impl SeriesKind {
    /// "dynamic" or "scroll".
    pub fn as_str(self) -> &'static str {
        match self {
            SeriesKind::Dynamic => "dynamic",
            SeriesKind::Scroll => "scroll",
        }
    }
}

/// The effects of `DATA.md`'s catalogue, as the truth writes them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EffectKind {
    /// Dry friction in bending (Dahl or tanh-regularised Coulomb).
    JointFriction,
    /// A drag growing with |κ̇|^p, p in 1.7–2.2, on top of a reduced linear damping.
    QuadraticDamping,
    /// Payne-type softening (or hardening) with a memory of the recent amplitude.
    AmplitudeStiffness,
    /// A nearly constant torque on the drive's or the idler's axle.
    BearingFriction,
    /// A power law |κ̇|^α, α in 0.3–0.7, replacing the linear damping.
    RateDependentDamping,
    /// Stiffness and damping falling as the belt warms.
    ThermalSoftening,
}

impl EffectKind {
    /// All six.
    pub const ALL: [EffectKind; 6] = [
        EffectKind::JointFriction,
        EffectKind::QuadraticDamping,
        EffectKind::AmplitudeStiffness,
        EffectKind::BearingFriction,
        EffectKind::RateDependentDamping,
        EffectKind::ThermalSoftening,
    ];

    /// The effect whose `DATA.md` identifier is `name`, if any.
    ///
    /// ```
    /// use trackbelt_truth::EffectKind;
    /// assert_eq!(EffectKind::from_name("bearing_friction"), Some(EffectKind::BearingFriction));
    /// assert_eq!(EffectKind::from_name("camera_drift"), None);
    /// for e in EffectKind::ALL {
    ///     assert_eq!(EffectKind::from_name(e.as_str()), Some(e));
    /// }
    /// ```
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|e| e.as_str() == name)
    }

    /// The `DATA.md` identifier.
    pub fn as_str(self) -> &'static str {
        match self {
            EffectKind::JointFriction => "joint_friction",
            EffectKind::QuadraticDamping => "quadratic_damping",
            EffectKind::AmplitudeStiffness => "amplitude_stiffness",
            EffectKind::BearingFriction => "bearing_friction",
            EffectKind::RateDependentDamping => "rate_dependent_damping",
            EffectKind::ThermalSoftening => "thermal_softening",
        }
    }

    /// The series kind where it shows.
    pub fn kind(self) -> SeriesKind {
        match self {
            EffectKind::JointFriction
            | EffectKind::QuadraticDamping
            | EffectKind::AmplitudeStiffness => SeriesKind::Dynamic,
            _ => SeriesKind::Scroll,
        }
    }
}

/// Disturbances outside the catalogue (a correct diagnosis says `unexplained`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DisturbanceKind {
    /// The camera's height reading drifts slowly (a sagging tripod).
    CameraDrift,
    /// The camera shakes: a decaying oscillation at a few hertz in the reading.
    CameraShake,
    /// The marker slips on the belt: a step in the reading.
    MarkerSlip,
    /// The torque sensor's zero drifts.
    TorqueDrift,
    /// The idler's running surface is eccentric: a load at its turning frequency.
    WheelRunout,
    /// The drive wheel slips in bursts (a wet patch on the belt).
    SlipBursts,
}

impl DisturbanceKind {
    /// All six.
    pub const ALL: [DisturbanceKind; 6] = [
        DisturbanceKind::CameraDrift,
        DisturbanceKind::CameraShake,
        DisturbanceKind::MarkerSlip,
        DisturbanceKind::TorqueDrift,
        DisturbanceKind::WheelRunout,
        DisturbanceKind::SlipBursts,
    ];

    /// The disturbance named `name` ([`DisturbanceKind::as_str`]), if any.
    ///
    /// ```
    /// use trackbelt_truth::DisturbanceKind;
    /// assert_eq!(DisturbanceKind::from_name("slip_bursts"), Some(DisturbanceKind::SlipBursts));
    /// assert_eq!(DisturbanceKind::from_name("joint_friction"), None);
    /// for d in DisturbanceKind::ALL {
    ///     assert_eq!(DisturbanceKind::from_name(d.as_str()), Some(d));
    /// }
    /// ```
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|d| d.as_str() == name)
    }

    /// Its name.
    pub fn as_str(self) -> &'static str {
        match self {
            DisturbanceKind::CameraDrift => "camera_drift",
            DisturbanceKind::CameraShake => "camera_shake",
            DisturbanceKind::MarkerSlip => "marker_slip",
            DisturbanceKind::TorqueDrift => "torque_drift",
            DisturbanceKind::WheelRunout => "wheel_runout",
            DisturbanceKind::SlipBursts => "slip_bursts",
        }
    }

    /// The series kind where it happens.
    pub fn kind(self) -> SeriesKind {
        match self {
            DisturbanceKind::CameraDrift
            | DisturbanceKind::CameraShake
            | DisturbanceKind::MarkerSlip => SeriesKind::Dynamic,
            _ => SeriesKind::Scroll,
        }
    }
}

/// What a dataset has in it beyond the clean belt.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Outcome {
    /// Nothing: the right answer is `none`.
    None,
    /// One catalogue effect: the right answer is its identifier.
    Effect(EffectKind),
    /// A disturbance outside the catalogue: the right answer is `unexplained`.
    Disturbance(DisturbanceKind),
}

impl Outcome {
    /// The outcome named `name` ([`Outcome::as_str`]: `none`, an effect's
    /// identifier or a disturbance's name), if any.
    ///
    /// ```
    /// use trackbelt_truth::{DisturbanceKind, EffectKind, Outcome};
    /// assert_eq!(Outcome::from_name("none"), Some(Outcome::None));
    /// assert_eq!(
    ///     Outcome::from_name("joint_friction"),
    ///     Some(Outcome::Effect(EffectKind::JointFriction))
    /// );
    /// assert_eq!(
    ///     Outcome::from_name("torque_drift"),
    ///     Some(Outcome::Disturbance(DisturbanceKind::TorqueDrift))
    /// );
    /// assert_eq!(Outcome::from_name("unexplained"), None);
    /// ```
    pub fn from_name(name: &str) -> Option<Self> {
        if name == "none" {
            return Some(Outcome::None);
        }
        EffectKind::from_name(name)
            .map(Outcome::Effect)
            .or_else(|| DisturbanceKind::from_name(name).map(Outcome::Disturbance))
    }

    /// The answer a correct diagnosis gives.
    pub fn expected(self) -> &'static str {
        match self {
            Outcome::None => "none",
            Outcome::Effect(e) => e.as_str(),
            Outcome::Disturbance(_) => "unexplained",
        }
    }

    /// A short name ("none", the effect's identifier, or the disturbance's name).
    pub fn as_str(self) -> &'static str {
        match self {
            Outcome::None => "none",
            Outcome::Effect(e) => e.as_str(),
            Outcome::Disturbance(d) => d.as_str(),
        }
    }

    /// The series kinds it can appear in.
    pub fn kinds(self) -> &'static [SeriesKind] {
        match self {
            Outcome::None => &[SeriesKind::Dynamic, SeriesKind::Scroll],
            Outcome::Effect(e) => match e.kind() {
                SeriesKind::Dynamic => &[SeriesKind::Dynamic],
                SeriesKind::Scroll => &[SeriesKind::Scroll],
            },
            Outcome::Disturbance(d) => match d.kind() {
                SeriesKind::Dynamic => &[SeriesKind::Dynamic],
                SeriesKind::Scroll => &[SeriesKind::Scroll],
            },
        }
    }
}

/// The belt as the dataset states it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Belt {
    /// Length (closed loop), m.
    pub length_m: f64,
    /// Width, m.
    pub width_m: f64,
    /// Thickness, m.
    pub thickness_m: f64,
    /// Mass, kg.
    pub mass_kg: f64,
    /// Number of grousers, if stated.
    pub grousers: Option<u32>,
}

impl Belt {
    /// The DTV Shredder belt of the paper.
    pub fn shredder() -> Self {
        Belt {
            length_m: 2.45,
            width_m: 0.16,
            thickness_m: 0.008,
            mass_kg: 6.4,
            grousers: Some(38),
        }
    }

    /// Factor of its bending stiffness against the Shredder's (width·t³).
    pub fn ei_factor(&self) -> f64 {
        (self.width_m / 0.16) * (self.thickness_m / 0.008).powi(3)
    }

    /// Factor of its characteristic curvatures against the Shredder's
    /// (the same surface strain: 1/t).
    pub fn kappa_factor(&self) -> f64 {
        0.008 / self.thickness_m
    }

    /// Weight against bending stiffness, `m·g·L²/EI` with the soft stiffness.
    pub fn gravity_number(&self) -> f64 {
        self.mass_kg * 9.81 * self.length_m * self.length_m
            / (BendingLaw::shredder().ei_soft * self.ei_factor())
    }
}

/// Camera of the drop test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Frame rate, Hz.
    pub rate_hz: f64,
    /// Time of the first frame after the release, s (< 1/rate).
    pub phase_s: f64,
    /// Marker noise (standard deviation), mm.
    pub noise_mm: f64,
    /// Rows lost.
    pub dropped_rows: usize,
    /// Error of the camera's height zero, mm.
    pub offset_mm: f64,
    /// Whether A's horizontal position is written too.
    pub with_x: bool,
}

/// Torque logger of the rig.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Logger {
    /// Rate, Hz.
    pub rate_hz: f64,
    /// Averages over each interval (else samples at its end).
    pub averaging: bool,
    /// Torque noise, as a fraction of the RMS torque.
    pub torque_noise_rel: f64,
    /// Torque noise floor, N·m.
    pub torque_noise_nm: f64,
    /// Speed noise, rad/s.
    pub omega_noise: f64,
    /// Whether the belt temperature is logged.
    pub with_temp: bool,
    /// Temperature sensor noise, K.
    pub temp_noise_k: f64,
}

/// The drop test.
#[derive(Debug, Clone, PartialEq)]
pub struct DropTest {
    /// Roller mass, kg.
    pub roller_kg: f64,
    /// Roller radius, m.
    pub roller_radius_m: f64,
    /// Length of the record, s.
    pub duration_s: f64,
    /// Static repeat runs (the belt turned by a quarter each time; the
    /// ring is uniform, so they differ by the tape-measure scatter).
    pub static_runs: usize,
    /// Tape-measure scatter of the static figures (standard deviation), mm.
    pub static_scatter_mm: f64,
    /// Camera.
    pub camera: Camera,
}

/// The rig test.
#[derive(Debug, Clone, PartialEq)]
pub struct RigTest {
    /// Drive wheel diameter, m.
    pub drive_d_m: f64,
    /// Idler diameter, m.
    pub idler_d_m: f64,
    /// Tensioner force, N.
    pub idler_force_n: f64,
    /// Speed profile knots (t s, ω rad/s): smooth ramps between them.
    pub profile: Vec<(f64, f64)>,
    /// Length of the record, s.
    pub duration_s: f64,
    /// Ambient temperature, °C.
    pub ambient_c: f64,
    /// Largest warming over the run, K.
    pub temp_rise_k: f64,
    /// Cooling time constant, s.
    pub tau_cool_s: f64,
    /// Logger.
    pub logger: Logger,
}

/// Which test, with its set-up.
#[derive(Debug, Clone, PartialEq)]
pub enum Test {
    /// Static runs and a roller drop test.
    Dynamic(DropTest),
    /// The two-wheel rig.
    Scroll(RigTest),
}

/// A disturbance with its size.
#[derive(Debug, Clone, PartialEq)]
pub enum Disturbance {
    /// Reading drifts by `rate·t + curve·t²`, mm.
    CameraDrift {
        /// mm/s.
        mm_per_s: f64,
        /// mm/s².
        mm_per_s2: f64,
    },
    /// Reading shakes: `a·e^(−d·(t−t0))·sin(2πf(t−t0))` after t0.
    CameraShake {
        /// Amplitude, mm.
        amplitude_mm: f64,
        /// Frequency, Hz.
        freq_hz: f64,
        /// Decay, 1/s.
        decay_per_s: f64,
        /// Start, s.
        start_s: f64,
    },
    /// Reading steps by `step_mm` at `at_s`.
    MarkerSlip {
        /// s.
        at_s: f64,
        /// mm.
        step_mm: f64,
    },
    /// Torque reading drifts by `rate·t`, plus a slow wander, both relative
    /// to the run's RMS torque.
    TorqueDrift {
        /// Drift, fraction of the RMS torque per second.
        rel_per_s: f64,
        /// Amplitude of a slow sinusoidal wander, fraction of the RMS torque.
        wander_rel: f64,
        /// Its period, s.
        wander_period_s: f64,
    },
    /// The idler's running surface is off its axle by `eccentricity_m`.
    WheelRunout {
        /// m.
        eccentricity_m: f64,
    },
    /// The drive slips in these windows (friction falls to `mu`).
    SlipBursts {
        /// (start s, end s).
        windows: Vec<(f64, f64)>,
        /// Friction coefficient inside them.
        mu: f64,
    },
}

/// Everything that makes one dataset, drawn by [`draw`] or written by hand.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// Seed of everything random in it (noise included).
    pub seed: u64,
    /// Dataset name (says nothing about the outcome).
    pub name: String,
    /// What is in it.
    pub outcome: Outcome,
    /// Size of the effect or disturbance (1: clearly visible; about 0.35:
    /// moderate).
    pub magnitude: f64,
    /// The belt.
    pub belt: Belt,
    /// Nodes of the simulation.
    pub nodes: usize,
    /// Axial stiffness EA, N.
    pub ea_n: f64,
    /// Bending behaviour (effects included).
    pub material: Material,
    /// Relative amplitude of the belt's non-uniformity along its length.
    pub nonuniformity: f64,
    /// Bearing friction, if any.
    pub bearing: Option<crate::scroll::Bearing>,
    /// Disturbance, if any.
    pub disturbance: Option<Disturbance>,
    /// The test and its instruments.
    pub test: Test,
    /// Which run of the same belt on the same bench this is: 0 for the
    /// first (what [`draw`] gives), 1, 2, … for the repeats of
    /// [`Scenario::repeat`], which draw their own set-up and noise.
    pub run: u32,
}

impl Scenario {
    /// The series kind.
    pub fn kind(&self) -> SeriesKind {
        match self.test {
            Test::Dynamic(_) => SeriesKind::Dynamic,
            Test::Scroll(_) => SeriesKind::Scroll,
        }
    }

    /// Repeat run `run` of this scenario: the same belt on the same bench,
    /// as a lab records several runs of one belt. The belt, its laws, the
    /// effect and the disturbance stay. A drop test gets another roller
    /// (0.6–1.6 times the first one's mass, another radius) and another
    /// camera set-up; a rig test another speed profile and warming on the
    /// same wheels, tensioner and logger. The record's length stays, and
    /// [`generate_runs`](crate::generate_runs) gives each run noise of its
    /// own. Run 0 is this scenario itself.
    ///
    /// ```
    /// use trackbelt_truth::{draw, Outcome, SeriesKind};
    /// let first = draw(Outcome::None, SeriesKind::Dynamic, 7).unwrap();
    /// let second = first.repeat(1);
    /// assert_eq!((second.run, &second.belt, second.material), (1, &first.belt, first.material));
    /// assert_ne!(second.test, first.test);
    /// assert_eq!(first.repeat(0), first);
    /// ```
    pub fn repeat(&self, run: u32) -> Scenario {
        let mut sc = self.clone();
        sc.run = run;
        if run == 0 {
            return sc;
        }
        let mut rng = Rng::stream(self.seed, 0x7265_7000 ^ u64::from(run));
        sc.test = match &self.test {
            Test::Dynamic(d) => {
                let rate_hz = [25.0, 30.0, 40.0, 50.0][rng.int(0, 3)];
                Test::Dynamic(DropTest {
                    roller_kg: (d.roller_kg * rng.range(0.6, 1.6)).clamp(0.4, 3.0),
                    roller_radius_m: rng.range(0.035, 0.06),
                    camera: draw_camera(&mut rng, rate_hz),
                    ..d.clone()
                })
            }
            Test::Scroll(r) => Test::Scroll(RigTest {
                profile: draw_profile(&mut rng, r.duration_s),
                ambient_c: rng.range(18.0, 28.0),
                temp_rise_k: rng.range(2.0, 30.0),
                ..r.clone()
            }),
        };
        sc
    }

    /// A drop test of this scenario's belt, as a lab may record one beside
    /// its rig runs: the same belt, bending law and effect, on the floor
    /// (uniform along its length, as every drop test's belt is, and at the
    /// reference temperature), with a roller, camera and static repeats
    /// drawn from a stream of their own (so the rig run stays as drawn).
    /// The bearing and any disturbance belong to the rig and are left out.
    /// Every run of the rig ([`Scenario::repeat`]) has the same drop test
    /// beside it: the belt's one drop test, not one per rig run.
    ///
    /// ```
    /// use trackbelt_truth::{draw, Outcome, SeriesKind};
    /// let rig = draw(Outcome::None, SeriesKind::Scroll, 7).unwrap();
    /// let drop = rig.drop_test_beside();
    /// assert_eq!((drop.kind(), &drop.belt, drop.material), (SeriesKind::Dynamic, &rig.belt, rig.material));
    /// ```
    pub fn drop_test_beside(&self) -> Scenario {
        let mut rng = Rng::stream(self.seed, 0x6472_6f70);
        let mut sc = self.clone();
        sc.run = 0;
        sc.test = draw_test(&mut rng, SeriesKind::Dynamic, &self.belt);
        sc.nonuniformity = 0.0;
        sc.ea_n = axial_stiffness_n(SeriesKind::Dynamic);
        sc.bearing = None;
        sc.disturbance = None;
        sc
    }
}

/// Axial stiffness EA (N) the truth simulates a belt with in a test of
/// `kind` (the rig's belt carries the tensioner's pull): every drop test,
/// [`draw_at`]'s or [`Scenario::drop_test_beside`]'s, uses the same.
fn axial_stiffness_n(kind: SeriesKind) -> f64 {
    match kind {
        SeriesKind::Dynamic => 5.0e4,
        SeriesKind::Scroll => 2.0e5,
    }
}

/// Nominal sizes at magnitude 1 (for the Shredder belt; scaled with EI for others).
mod nominal {
    /// Sliding moment of the bending friction, N·m.
    pub const FRICTION_NM: f64 = 0.08;
    /// Drag at the reference rate, as a multiple of the linear damping moment.
    pub const DRAG_RATIO: f64 = 1.5;
    /// Curvature rate where the drag is measured, 1/(m·s).
    pub const DRAG_RATE: f64 = 25.0;
    /// Excess dynamic stiffness of the Payne softening at small amplitude.
    pub const PAYNE_DEPTH: f64 = 0.45;
    /// Bearing torque, N·m.
    pub const BEARING_NM: f64 = 0.6;
    /// Curvature rate where the power law meets the linear law, 1/(m·s).
    pub const POWER_RATE: f64 = 30.0;
}

fn draw_belt(rng: &mut Rng, kind: SeriesKind) -> Belt {
    if rng.chance(0.35) {
        return Belt::shredder();
    }
    let g0 = Belt::shredder().gravity_number();
    let min_len = if kind == SeriesKind::Scroll { 1.5 } else { 1.0 };
    for _ in 0..500 {
        let length_m = rng.range(min_len, 2.6);
        let thickness_m = rng.range(0.005, 0.012);
        let mass_kg = rng.range(1.5, 7.0);
        let density = rng.range(1700.0, 2300.0);
        let width_m = mass_kg / (density * length_m * thickness_m);
        let b = Belt {
            length_m,
            width_m,
            thickness_m,
            mass_kg,
            grousers: None,
        };
        let g = b.gravity_number() / g0;
        if (0.08..=0.26).contains(&width_m) && (0.4..=1.6).contains(&g) {
            let grousers = if rng.chance(0.5) {
                Some((length_m / rng.range(0.05, 0.08)).round() as u32)
            } else {
                None
            };
            return Belt { grousers, ..b };
        }
    }
    Belt::shredder()
}

fn jitter_law(rng: &mut Rng, l: BendingLaw) -> BendingLaw {
    let mut j = |x: f64| x * rng.around(0.2);
    BendingLaw {
        ei_soft: j(l.ei_soft),
        ei_zero: j(l.ei_zero),
        kappa_t: j(l.kappa_t),
        ei_hard: j(l.ei_hard),
        kappa_h: j(l.kappa_h),
        w_h: j(l.w_h),
        ei_back: j(l.ei_back),
        kappa_b: j(l.kappa_b),
        w_b: j(l.w_b),
    }
}

/// A smooth random speed profile: 2–5 plateaus in 0.5–8 rad/s joined by
/// ramps, starting from rest.
fn draw_profile(rng: &mut Rng, duration_s: f64) -> Vec<(f64, f64)> {
    let plateaus = rng.int(2, 5);
    let mut knots = vec![(0.0, 0.0)];
    let mut t = 0.0;
    let share = duration_s / plateaus as f64;
    let mut last = 0.0;
    for i in 0..plateaus {
        let mut level = rng.range(0.5, 8.0);
        // Plateaus that differ enough to be told apart.
        for _ in 0..10 {
            if (level - last).abs() > 1.0 {
                break;
            }
            level = rng.range(0.5, 8.0);
        }
        let ramp = rng.range(0.4, 1.5).min(0.4 * share);
        let hold = if i + 1 == plateaus {
            duration_s - t - ramp
        } else {
            share * rng.range(0.8, 1.2) - ramp
        };
        t += ramp;
        knots.push((t, level));
        t += hold.max(0.5);
        knots.push((t.min(duration_s), level));
        last = level;
    }
    knots
}

/// A camera of frame rate `rate_hz` (drawn before, where the caller's
/// sequence of draws puts it), the rest drawn from `rng`.
fn draw_camera(rng: &mut Rng, rate_hz: f64) -> Camera {
    Camera {
        rate_hz,
        phase_s: rng.unit() / rate_hz,
        noise_mm: rng.range(0.5, 1.5),
        dropped_rows: rng.int(1, 6),
        offset_mm: rng.range(-2.0, 2.0),
        with_x: rng.chance(0.5),
    }
}

/// The test and its instruments for `belt`, drawn from `rng`.
fn draw_test(rng: &mut Rng, kind: SeriesKind, belt: &Belt) -> Test {
    match kind {
        SeriesKind::Dynamic => {
            let roller_kg = if *belt == Belt::shredder() {
                1.3
            } else {
                (1.3 * belt.mass_kg / 6.4 * rng.range(0.8, 1.25)).clamp(0.4, 3.0)
            };
            let rate_hz = [25.0, 30.0, 40.0, 50.0][rng.int(0, 3)];
            Test::Dynamic(DropTest {
                roller_kg,
                roller_radius_m: rng.range(0.035, 0.06),
                duration_s: rng.range(6.0, 10.0),
                static_runs: rng.int(2, 4),
                static_scatter_mm: rng.range(1.0, 4.0),
                camera: draw_camera(rng, rate_hz),
            })
        }
        SeriesKind::Scroll => {
            let duration_s = rng.range(8.0, 15.0);
            let mut drive_d_m = rng.range(0.2, 0.4);
            let mut idler_d_m = rng.range(0.2, 0.4);
            // Keep straight spans of at least 15 cm.
            let room = (belt.length_m - 0.3) / std::f64::consts::PI;
            if drive_d_m + idler_d_m > room {
                let f = room / (drive_d_m + idler_d_m);
                drive_d_m = (drive_d_m * f).max(0.2);
                idler_d_m = (idler_d_m * f).max(0.2);
            }
            Test::Scroll(RigTest {
                drive_d_m,
                idler_d_m,
                idler_force_n: rng.range(300.0, 800.0),
                profile: draw_profile(rng, duration_s),
                duration_s,
                ambient_c: rng.range(18.0, 28.0),
                temp_rise_k: rng.range(2.0, 30.0),
                tau_cool_s: rng.range(20.0, 60.0),
                logger: Logger {
                    rate_hz: rng.int(20, 100) as f64,
                    averaging: rng.chance(0.5),
                    torque_noise_rel: rng.range(0.01, 0.03),
                    torque_noise_nm: 0.005,
                    omega_noise: rng.range(0.002, 0.01),
                    with_temp: rng.chance(0.75),
                    temp_noise_k: rng.range(0.05, 0.3),
                },
            })
        }
    }
}

/// Draw a scenario of `outcome` in a series of `kind`, every variation at
/// random from `seed`, the effect's magnitude uniform in 0.35–1.
pub fn draw(outcome: Outcome, kind: SeriesKind, seed: u64) -> Result<Scenario, Error> {
    let mut rng = Rng::stream(seed, 0x6d61_676e);
    let m = rng.range(0.35, 1.0);
    draw_at(outcome, kind, seed, m)
}

/// As [`draw`], with the magnitude given (1: clearly visible, 0.35: moderate).
pub fn draw_at(
    outcome: Outcome,
    kind: SeriesKind,
    seed: u64,
    magnitude: f64,
) -> Result<Scenario, Error> {
    if !outcome.kinds().contains(&kind) {
        return Err(Error::KindMismatch {
            outcome: outcome.as_str().to_string(),
            kind: kind.as_str(),
        });
    }
    if !(magnitude.is_finite() && magnitude > 0.0 && magnitude <= 5.0) {
        return Err(Error::Invalid(format!("magnitude {magnitude}")));
    }
    let mut rng = Rng::stream(seed, 0x7363_656e);
    let belt = draw_belt(&mut rng, kind);
    let ei = belt.ei_factor();
    let kf = belt.kappa_factor();
    let elastic = jitter_law(&mut rng, BendingLaw::shredder().scaled(ei, kf));
    let c_lin = BendingLaw::SHREDDER_DAMPING * ei * rng.around(0.2);
    let nodes = 2 * rng.int(13, 18);
    let mut material = Material {
        elastic,
        damping: DampingLaw::Linear { c: c_lin },
        friction: FrictionLaw::None,
        payne: None,
        thermal: None,
    };
    // Along the length the belt is slightly non-uniform; on the floor that
    // would make the ring roll slowly towards its softest spot (the model has
    // no rolling resistance but its bending damping), so only the rig's belt
    // carries it.
    let nonuniformity = match kind {
        SeriesKind::Dynamic => 0.0,
        SeriesKind::Scroll => rng.range(0.01, 0.03),
    };
    let test = draw_test(&mut rng, kind, &belt);
    let mut sc = Scenario {
        seed,
        name: format!(
            "bench-{:06x}",
            Rng::stream(seed, 0x6e61_6d65).next_u64() & 0xff_ffff
        ),
        outcome,
        magnitude,
        belt,
        nodes,
        ea_n: axial_stiffness_n(kind),
        material,
        nonuniformity,
        bearing: None,
        disturbance: None,
        test,
        run: 0,
    };
    // The effect or disturbance.
    let mut rng = Rng::stream(seed, 0x6566_6665);
    let mg = magnitude;
    match outcome {
        Outcome::None => {}
        Outcome::Effect(e) => match e {
            EffectKind::JointFriction => {
                let m_c = nominal::FRICTION_NM * ei * mg * rng.around(0.3);
                material.friction = if rng.chance(0.5) {
                    FrictionLaw::Dahl {
                        m_c,
                        kappa_s: rng.range(0.05, 0.2) * kf,
                    }
                } else {
                    FrictionLaw::Tanh {
                        m_c,
                        rate: m_c / (c_lin * rng.range(0.8, 1.5)),
                    }
                };
            }
            EffectKind::QuadraticDamping => {
                let p = rng.range(1.7, 2.2);
                let r = nominal::DRAG_RATE * kf;
                let c = c_lin * (1.0 - 0.3 * mg.min(1.0));
                let cq = nominal::DRAG_RATIO * mg * c_lin * r / r.powf(p);
                material.damping = DampingLaw::Drag {
                    c,
                    cq,
                    p,
                    cap: 1.5 * r,
                };
            }
            EffectKind::AmplitudeStiffness => {
                let depth = if rng.chance(0.75) {
                    nominal::PAYNE_DEPTH * mg * rng.around(0.3)
                } else {
                    -0.7 * nominal::PAYNE_DEPTH * mg * rng.around(0.3)
                };
                material.payne = Some(Payne {
                    depth,
                    amp_c: rng.range(0.3, 1.0) * kf,
                    tau_mem_s: rng.range(0.3, 1.0),
                    tau_mean_s: rng.range(0.8, 2.0),
                });
            }
            EffectKind::BearingFriction => {
                sc.bearing = Some(crate::scroll::Bearing {
                    torque_nm: nominal::BEARING_NM * ei.sqrt() * mg * rng.around(0.3),
                    omega_reg: rng.range(0.05, 0.2),
                    viscous_per_rad_s: rng.range(0.0, 0.01),
                    on_idler: rng.chance(0.5),
                });
            }
            EffectKind::RateDependentDamping => {
                let alpha = 1.0 - mg.min(1.0) * rng.range(0.3, 0.7);
                let rate_ref = nominal::POWER_RATE * kf * rng.around(0.3);
                material.damping = DampingLaw::Power {
                    c: c_lin,
                    alpha,
                    rate_ref,
                    eps: 0.15 * rate_ref,
                };
            }
            EffectKind::ThermalSoftening => {
                material.thermal = Some(Thermal {
                    beta_per_k: mg * rng.range(0.006, 0.012),
                    c1: mg * rng.range(0.3, 0.6),
                    c2_k: rng.range(60.0, 120.0),
                });
                if let Test::Scroll(r) = &mut sc.test {
                    r.temp_rise_k = rng.range(10.0, 40.0);
                    r.logger.with_temp = true;
                }
            }
        },
        Outcome::Disturbance(d) => {
            let sign = if rng.chance(0.5) { 1.0 } else { -1.0 };
            let dur = match &sc.test {
                Test::Dynamic(t) => t.duration_s,
                Test::Scroll(r) => r.duration_s,
            };
            sc.disturbance = Some(match d {
                DisturbanceKind::CameraDrift => Disturbance::CameraDrift {
                    mm_per_s: sign * mg * rng.range(0.8, 2.0),
                    mm_per_s2: sign * mg * rng.range(0.0, 0.1),
                },
                DisturbanceKind::CameraShake => Disturbance::CameraShake {
                    amplitude_mm: mg * rng.range(3.0, 8.0),
                    freq_hz: rng.range(3.0, 9.0),
                    decay_per_s: rng.range(0.2, 0.8),
                    start_s: rng.range(0.0, 2.0),
                },
                DisturbanceKind::MarkerSlip => Disturbance::MarkerSlip {
                    at_s: rng.range(1.5, dur - 2.0),
                    step_mm: sign * mg * rng.range(3.0, 8.0),
                },
                DisturbanceKind::TorqueDrift => Disturbance::TorqueDrift {
                    rel_per_s: sign * mg * rng.range(0.01, 0.03),
                    wander_rel: mg * rng.range(0.0, 0.05),
                    wander_period_s: rng.range(3.0, 8.0),
                },
                DisturbanceKind::WheelRunout => Disturbance::WheelRunout {
                    eccentricity_m: mg * rng.range(0.0008, 0.002),
                },
                DisturbanceKind::SlipBursts => {
                    let count = rng.int(2, 4);
                    let windows = (0..count)
                        .map(|i| {
                            let slot = (dur - 2.0) / count as f64;
                            let start = 1.5 + slot * (i as f64 + rng.range(0.0, 0.5));
                            (start, start + rng.range(0.3, 0.8))
                        })
                        .collect();
                    Disturbance::SlipBursts {
                        windows,
                        mu: rng.range(0.002, 0.008) / mg.max(0.2),
                    }
                }
            });
        }
    }
    sc.material = material;
    Ok(sc)
}

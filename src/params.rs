//! Physical parameters: the belt, the floor, contacts, and the paper's joint
//! parameters for methods I and II.
//!
//! All values are SI (m, kg, s, N, N·m, rad); names carry their unit.
//!
//! ```
//! use trackbelt::params::{Method, Model, Variant};
//! let model = Model::<f64>::paper(Variant::E38, Method::I).unwrap();
//! assert_eq!(model.belt.links, 38);
//! assert!((model.belt.link_length_m() - 2.45 / 38.0).abs() < 1e-15);
//! ```

// `invalid` is re-exported for the estimator's builder.
pub(crate) use crate::error::invalid;
use crate::error::{Error, Result};
use crate::joint::JointLaw;
use crate::real::Real;

/// Model variant: the number of links (paper section 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Variant {
    /// 38 links (one per grouser).
    E38,
    /// 56 links.
    E56,
    /// 76 links.
    E76,
}

impl Variant {
    /// All variants, in the paper's order.
    pub const ALL: [Variant; 3] = [Variant::E38, Variant::E56, Variant::E76];

    /// Number of links.
    pub const fn links(self) -> usize {
        match self {
            Variant::E38 => 38,
            Variant::E56 => 56,
            Variant::E76 => 76,
        }
    }

    /// Name as in the paper ("E38").
    pub const fn name(self) -> &'static str {
        match self {
            Variant::E38 => "E38",
            Variant::E56 => "E56",
            Variant::E76 => "E76",
        }
    }

    /// Parse "E38", "e56", "76", ….
    pub fn parse(s: &str) -> Option<Variant> {
        let t = s.trim().trim_start_matches(['E', 'e']);
        match t {
            "38" => Some(Variant::E38),
            "56" => Some(Variant::E56),
            "76" => Some(Variant::E76),
            _ => None,
        }
    }
}

/// Stiffness method (paper section 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Method {
    /// Constant stiffness.
    I,
    /// Bivalent stiffness.
    II,
    /// Tabulated (variable) stiffness.
    III,
}

impl Method {
    /// All methods.
    pub const ALL: [Method; 3] = [Method::I, Method::II, Method::III];

    /// Roman numeral as in the paper.
    pub const fn name(self) -> &'static str {
        match self {
            Method::I => "I",
            Method::II => "II",
            Method::III => "III",
        }
    }

    /// Parse "I", "II", "III" (also "1", "2", "3").
    pub fn parse(s: &str) -> Option<Method> {
        match s.trim() {
            "I" | "i" | "1" => Some(Method::I),
            "II" | "ii" | "2" => Some(Method::II),
            "III" | "iii" | "3" => Some(Method::III),
            _ => None,
        }
    }
}

/// The belt: a closed loop of `links` equal rigid links.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Belt<T> {
    /// Loop length, m.
    pub length_m: T,
    /// Width, m (not used by the planar model; kept for reports).
    pub width_m: T,
    /// Thickness, m. Contacts act on the surfaces, half of it off the axis.
    pub thickness_m: T,
    /// Total mass, kg.
    pub mass_kg: T,
    /// Number of links N.
    pub links: usize,
}

/// Fewest links a closed chain can have and still bend.
pub const MIN_LINKS: usize = 3;

impl<T: Real> Belt<T> {
    /// The DTV Shredder belt of the paper: 2450 mm, 160 mm, 8 mm, 6.4 kg.
    pub fn shredder(links: usize) -> Self {
        Belt {
            length_m: T::from_f64(2.45),
            width_m: T::from_f64(0.16),
            thickness_m: T::from_f64(0.008),
            mass_kg: T::from_f64(6.4),
            links,
        }
    }

    /// Link length L/N, m.
    pub fn link_length_m(&self) -> T {
        self.length_m / T::from_usize(self.links)
    }

    /// Link mass m/N, kg.
    pub fn link_mass_kg(&self) -> T {
        self.mass_kg / T::from_usize(self.links)
    }

    /// Check the belt.
    pub fn validate(&self) -> Result<()> {
        let pos = |x: T| x.is_finite() && x > T::ZERO;
        if !pos(self.length_m) {
            return Err(invalid("belt.length_m", "must be positive and finite"));
        }
        if !pos(self.mass_kg) {
            return Err(invalid("belt.mass_kg", "must be positive and finite"));
        }
        if !pos(self.thickness_m) {
            return Err(invalid("belt.thickness_m", "must be positive and finite"));
        }
        if !self.width_m.is_finite() || self.width_m < T::ZERO {
            return Err(invalid("belt.width_m", "must be finite and not negative"));
        }
        if self.links < MIN_LINKS {
            return Err(invalid(
                "belt.links",
                "a closed chain needs at least 3 links",
            ));
        }
        if self.thickness_m * T::from_f64(2.0) >= self.link_length_m() * T::from_usize(self.links) {
            return Err(invalid("belt.thickness_m", "thicker than the loop allows"));
        }
        if !pos(self.link_length_m()) || !pos(self.link_mass_kg()) {
            return Err(invalid(
                "belt.links",
                "too many links for the length and mass (a link's length or mass underflows)",
            ));
        }
        Ok(())
    }

    /// Convert to another number type.
    pub fn cast<U: Real>(&self) -> Belt<U> {
        Belt {
            length_m: U::from_f64(self.length_m.to_f64()),
            width_m: U::from_f64(self.width_m.to_f64()),
            thickness_m: U::from_f64(self.thickness_m.to_f64()),
            mass_kg: U::from_f64(self.mass_kg.to_f64()),
            links: self.links,
        }
    }
}

/// A flat floor with a penalty contact on the belt's outer surface and
/// regularised Coulomb friction.
///
/// The paper does not give these; the defaults are chosen so that the floor
/// is stiff against the belt's weight (about 0.1 mm of penetration) and the
/// figures barely depend on them (see the floor-sensitivity test).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Floor<T> {
    /// Normal stiffness per contact point, N/m (two points per link).
    pub stiffness_n_per_m: T,
    /// Normal damping per contact point, N·s/m.
    pub damping_n_s_per_m: T,
    /// Coulomb friction coefficient.
    pub friction: T,
    /// Slip speed below which friction is proportional to slip, m/s.
    pub slip_speed_m_s: T,
}

impl<T: Real> Default for Floor<T> {
    fn default() -> Self {
        Floor {
            stiffness_n_per_m: T::from_f64(1.0e5),
            damping_n_s_per_m: T::from_f64(50.0),
            friction: T::from_f64(0.6),
            slip_speed_m_s: T::from_f64(0.01),
        }
    }
}

/// Penalty contact between the inner surfaces of non-adjacent links.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SelfContact<T> {
    /// `false` lets the belt pass through itself.
    pub enabled: bool,
    /// Normal stiffness per contact point, N/m.
    pub stiffness_n_per_m: T,
    /// Normal damping per contact point, N·s/m.
    pub damping_n_s_per_m: T,
}

impl<T: Real> Default for SelfContact<T> {
    fn default() -> Self {
        SelfContact {
            enabled: true,
            stiffness_n_per_m: T::from_f64(1.0e5),
            damping_n_s_per_m: T::from_f64(50.0),
        }
    }
}

/// Everything physical about one simulation.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(bound(
        serialize = "T: Real + serde::Serialize",
        deserialize = "T: Real + serde::Deserialize<'de>"
    ))
)]
pub struct Model<T> {
    /// The belt.
    pub belt: Belt<T>,
    /// The joint law (stiffness + damping) shared by all joints.
    pub joint: JointLaw<T>,
    /// The floor (bench tests).
    pub floor: Floor<T>,
    /// Self-contact of the belt.
    pub self_contact: SelfContact<T>,
    /// Gravitational acceleration, m/s² (acts along −y).
    pub gravity_m_s2: T,
}

impl<T: Real> Model<T> {
    /// A model with the given belt and joint law and default environment.
    pub fn new(belt: Belt<T>, joint: JointLaw<T>) -> Result<Self> {
        let m = Model {
            belt,
            joint,
            floor: Floor::default(),
            self_contact: SelfContact::default(),
            gravity_m_s2: T::from_f64(9.81),
        };
        m.validate()?;
        Ok(m)
    }

    /// The Shredder belt with the paper's parameters for methods I and II
    /// (method III has no published numbers: use a calibrated table, see
    /// [`paper::joint_law`]).
    pub fn paper(variant: Variant, method: Method) -> Result<Self> {
        let law = paper::joint_law(variant, method).ok_or(Error::InvalidParameter {
            field: "method",
            reason: "the paper publishes no table for method III; load a calibrated params file",
        })?;
        Model::new(Belt::shredder(variant.links()), law.cast())
    }

    /// Check every parameter.
    pub fn validate(&self) -> Result<()> {
        self.belt.validate()?;
        self.joint.validate()?;
        let f = &self.floor;
        let nonneg = |x: T| x.is_finite() && x >= T::ZERO;
        if !(f.stiffness_n_per_m.is_finite() && f.stiffness_n_per_m > T::ZERO) {
            return Err(invalid(
                "floor.stiffness_n_per_m",
                "must be positive and finite",
            ));
        }
        if !nonneg(f.damping_n_s_per_m) {
            return Err(invalid(
                "floor.damping_n_s_per_m",
                "must be finite and not negative",
            ));
        }
        if !nonneg(f.friction) {
            return Err(invalid("floor.friction", "must be finite and not negative"));
        }
        if !(f.slip_speed_m_s.is_finite() && f.slip_speed_m_s > T::ZERO) {
            return Err(invalid(
                "floor.slip_speed_m_s",
                "must be positive and finite",
            ));
        }
        let s = &self.self_contact;
        if !(s.stiffness_n_per_m.is_finite() && s.stiffness_n_per_m > T::ZERO) {
            return Err(invalid(
                "self_contact.stiffness_n_per_m",
                "must be positive and finite",
            ));
        }
        if !nonneg(s.damping_n_s_per_m) {
            return Err(invalid(
                "self_contact.damping_n_s_per_m",
                "must be finite and not negative",
            ));
        }
        if !nonneg(self.gravity_m_s2) {
            return Err(invalid("gravity_m_s2", "must be finite and not negative"));
        }
        Ok(())
    }

    /// Convert to another number type.
    pub fn cast<U: Real>(&self) -> Model<U> {
        let c = |x: T| U::from_f64(x.to_f64());
        Model {
            belt: self.belt.cast(),
            joint: self.joint.cast(),
            floor: Floor {
                stiffness_n_per_m: c(self.floor.stiffness_n_per_m),
                damping_n_s_per_m: c(self.floor.damping_n_s_per_m),
                friction: c(self.floor.friction),
                slip_speed_m_s: c(self.floor.slip_speed_m_s),
            },
            self_contact: SelfContact {
                enabled: self.self_contact.enabled,
                stiffness_n_per_m: c(self.self_contact.stiffness_n_per_m),
                damping_n_s_per_m: c(self.self_contact.damping_n_s_per_m),
            },
            gravity_m_s2: c(self.gravity_m_s2),
        }
    }
}

/// The roller's mass of the dynamic test, checked (finite, not negative),
/// kg.
pub(crate) fn roller_mass_kg<T: Real>(kg: T) -> Result<T> {
    if !kg.is_finite() || kg < T::ZERO {
        return Err(invalid("roller_kg", "must be finite and not negative"));
    }
    Ok(kg)
}

/// The paper's published parameters (Tables 2, 4, 6) and simulated figures.
pub mod paper {
    use super::{Method, Variant};
    use crate::effects::Effects;
    use crate::joint::JointLaw;
    use crate::stiffness::Stiffness;

    /// N·mm → N·m.
    const MM: f64 = 1.0e-3;

    /// Joint law of methods I and II in SI units; `None` for method III.
    pub fn joint_law(variant: Variant, method: Method) -> Option<JointLaw<f64>> {
        let (kz, cz1, kz1, kz2, cz2) = match variant {
            Variant::E38 => (8_600.0, 450.0, 125_000.0, 8_600.0, 200.0),
            Variant::E56 => (12_600.0, 650.0, 190_000.0, 12_600.0, 260.0),
            Variant::E76 => (17_200.0, 950.0, 258_000.0, 17_200.0, 360.0),
        };
        match method {
            Method::I => Some(JointLaw {
                stiffness: Stiffness::Constant { kz: kz * MM },
                damping: cz1 * MM,
                effects: Effects::none(),
            }),
            Method::II => Some(JointLaw {
                stiffness: Stiffness::Bivalent {
                    kz_pos: kz1 * MM,
                    kz_neg: kz2 * MM,
                },
                damping: cz2 * MM,
                effects: Effects::none(),
            }),
            Method::III => None,
        }
    }

    /// Method III damping cz of Table 6, N·m·s/rad.
    pub fn method3_damping(variant: Variant) -> f64 {
        MM * match variant {
            Variant::E38 => 360.0,
            Variant::E56 => 500.0,
            Variant::E76 => 700.0,
        }
    }

    /// Bench-test figures as printed in the paper.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct Figures {
        /// Static height, mm.
        pub hs_mm: f64,
        /// Static width, mm.
        pub ws_mm: f64,
        /// Loaded height, mm.
        pub hd_mm: f64,
        /// Loaded width, mm.
        pub wd_mm: f64,
        /// Period, s.
        pub period_s: f64,
        /// Logarithmic decrement.
        pub log_decrement: f64,
        /// Joint-angle range at A, degrees (Tables 3, 5, 7).
        pub angle_a_deg: [f64; 2],
        /// Joint-angle range at C, degrees.
        pub angle_c_deg: [f64; 2],
    }

    /// Table 1 mean of the eight measurements (no angle ranges measured:
    /// those fields are NaN).
    pub const EXPERIMENT_MEAN: Figures = Figures {
        hs_mm: 324.0,
        ws_mm: 1062.0,
        hd_mm: 225.0,
        wd_mm: 1082.0,
        period_s: 0.74,
        log_decrement: 0.73,
        angle_a_deg: [f64::NAN, f64::NAN],
        angle_c_deg: [f64::NAN, f64::NAN],
    };

    /// The paper's simulated figures (Tables 2/3, 4/5, 6/7).
    pub fn simulated(variant: Variant, method: Method) -> Figures {
        let f = |hs, ws, hd, wd, t, l, a: [f64; 2], c: [f64; 2]| Figures {
            hs_mm: hs,
            ws_mm: ws,
            hd_mm: hd,
            wd_mm: wd,
            period_s: t,
            log_decrement: l,
            angle_a_deg: a,
            angle_c_deg: c,
        };
        use Method::*;
        use Variant::*;
        match (method, variant) {
            (I, E38) => f(324., 1042., 122., 1056., 1.5, 0.69, [2., 19.], [-40., -24.]),
            (I, E56) => f(
                322.,
                1055.,
                124.,
                1072.,
                1.5,
                0.68,
                [1.5, 13.],
                [-27., -16.],
            ),
            (I, E76) => f(323., 1057., 125., 1073., 1.5, 0.68, [1., 9.], [-21., -14.]),
            (II, E38) => f(322., 1045., 249., 1073., 0.82, 0.74, [0., 2.], [-39., -28.]),
            (II, E56) => f(324., 1054., 255., 1071., 0.81, 0.78, [0., 1.], [-26., -19.]),
            (II, E76) => f(327., 1055., 257., 1086., 0.8, 0.69, [0., 1.], [-18., -14.]),
            (III, E38) => f(329., 1057., 225., 1078., 0.76, 0.69, [0., 2.], [-37., -34.]),
            (III, E56) => f(323., 1070., 223., 1093., 0.77, 0.78, [0., 3.], [-25., -23.]),
            (III, E76) => f(322., 1065., 225., 1101., 0.74, 0.76, [0., 2.], [-19., -17.]),
        }
    }

    /// Table 8: the paper's relative errors (%) against the Table 1 mean, in
    /// the order Hs, Ws, Hd, Wd, T, Λ.
    pub fn table8(variant: Variant, method: Method) -> [f64; 6] {
        use Method::*;
        use Variant::*;
        match (method, variant) {
            (I, E38) => [0., 2., 46., 2., 103., 5.],
            (I, E56) => [1., 1., 45., 1., 103., 7.],
            (I, E76) => [0., 0., 44., 1., 103., 7.],
            (II, E38) => [1., 2., 11., 1., 11., 1.],
            (II, E56) => [0., 1., 13., 1., 9., 7.],
            (II, E76) => [1., 1., 14., 0., 8., 5.],
            (III, E38) => [2., 0., 0., 0., 3., 5.],
            (III, E56) => [0., 1., 1., 1., 4., 7.],
            (III, E76) => [1., 0., 0., 2., 0., 4.],
        }
    }
}

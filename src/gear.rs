//! A robot's running gear: the wheels the belt wraps, the tensioner and the
//! ground (plain data; what the simulation and the estimator are built
//! from).
//!
//! The frame is the robot's side view: x forward, y up, metres, the drive
//! wheel usually at the origin. The belt wraps the convex hull of the
//! wheels; it turns clockwise for a positive drive speed.
//!
//! * **Wheels** (up to [`MAX_WHEELS`]): exactly one [`WheelRole::Drive`]
//!   (it drives the belt by friction; the drive torque is measured on its
//!   axle), exactly one [`WheelRole::Idler`] (it carries the tensioner), and
//!   any number of [`WheelRole::Road`] wheels (they press the lower run onto
//!   the ground) and [`WheelRole::Support`] rollers (they carry the upper
//!   run).
//! * **Tensioner**: a force on the idler's axle, which then slides along the
//!   line from the drive wheel's centre through the idler's given centre
//!   (the given centre is where it starts), or a fixed idler centre.
//! * **Ground** (optional): flat, horizontal ground under the road wheels,
//!   carrying the part of the robot's mass that rests on this track.
//!
//! The paper's two-wheel rig is the preset [`RunningGear::paper_rig`].
//!
//! ```
//! use trackbelt::gear::{RunningGear, Tensioner, Wheel, WheelRole};
//! use trackbelt::rig::RigConfig;
//!
//! // The paper's rig …
//! let rig = RunningGear::<f64>::paper_rig(&RigConfig::default(), 0.74)?;
//! assert_eq!(rig.wheels.len(), 2);
//! assert!(rig.two_wheel_rig_config().is_some());
//!
//! // … and a small robot: drive at the back, idler in front, two road wheels.
//! let mut gear = RunningGear::<f64>::new(Tensioner::Force { force_n: 400.0 });
//! gear.push(Wheel { role: WheelRole::Drive, x_m: 0.0, y_m: 0.0, diameter_m: 0.16 })?;
//! gear.push(Wheel { role: WheelRole::Idler, x_m: 0.52, y_m: 0.0, diameter_m: 0.14 })?;
//! gear.push(Wheel { role: WheelRole::Road, x_m: 0.17, y_m: -0.06, diameter_m: 0.09 })?;
//! gear.push(Wheel { role: WheelRole::Road, x_m: 0.35, y_m: -0.06, diameter_m: 0.09 })?;
//! gear.ground = Some(trackbelt::gear::Ground { load_kg: 12.0 });
//! gear.validate()?;
//! assert!(gear.two_wheel_rig_config().is_none());
//! # Ok::<(), trackbelt::Error>(())
//! ```

use crate::error::{invalid, Error, Result};
use crate::real::Real;
use crate::rig::RigConfig;

/// Most wheels a running gear can have.
pub const MAX_WHEELS: usize = 8;

/// What a wheel does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WheelRole {
    /// The driven sprocket or wheel (exactly one).
    Drive,
    /// The idler on the tensioner (exactly one).
    Idler,
    /// A road wheel pressing the lower run onto the ground.
    Road,
    /// A support roller under the upper run.
    Support,
}

/// One wheel (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Wheel<T> {
    /// What it does.
    pub role: WheelRole,
    /// Centre, forward, m.
    pub x_m: T,
    /// Centre, up, m.
    pub y_m: T,
    /// Diameter where the belt's inner surface touches it, m.
    pub diameter_m: T,
}

/// How the belt is kept tight.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Tensioner<T> {
    /// A constant force on the idler's axle, pushing it away from the drive
    /// wheel along the line through both centres, N.
    Force {
        /// The force, N.
        force_n: T,
    },
    /// The idler's centre is fixed where it is given: the belt's tension
    /// follows from its length against the path round the wheels (see
    /// [`Rig::from_gear`](crate::rig::Rig::from_gear); a belt too short or
    /// too long for the centre is an error).
    FixedCentre,
}

/// Flat ground under the road wheels.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Ground<T> {
    /// The robot's mass carried by this track, kg.
    pub load_kg: T,
}

/// The belt–wheel contact law and the idler's slider (SI). The defaults
/// are the paper rig's ([`RigConfig::default`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct WheelContact<T> {
    /// Normal stiffness of the belt–wheel contact, N/m.
    pub stiffness_n_per_m: T,
    /// Normal damping of the belt–wheel contact, N·s/m.
    pub damping_n_s_per_m: T,
    /// Friction coefficient between belt and drive wheel.
    pub drive_friction: T,
    /// Slip speed below which the drive friction is regularised, m/s.
    pub slip_speed_m_s: T,
    /// Mass moving with the idler's axle, kg.
    pub idler_mass_kg: T,
    /// Viscous damping of the idler's slider, N·s/m.
    pub idler_damping_n_s_per_m: T,
}

impl<T: Real> Default for WheelContact<T> {
    fn default() -> Self {
        let r = RigConfig::<T>::default();
        WheelContact {
            stiffness_n_per_m: r.wheel_stiffness_n_per_m,
            damping_n_s_per_m: r.wheel_damping_n_s_per_m,
            drive_friction: r.drive_friction,
            slip_speed_m_s: r.slip_speed_m_s,
            idler_mass_kg: r.idler_mass_kg,
            idler_damping_n_s_per_m: r.idler_damping_n_s_per_m,
        }
    }
}

/// The running gear: wheels, tensioner, ground, bearings.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RunningGear<T> {
    /// The wheels, in any order.
    pub wheels: heapless::Vec<Wheel<T>, MAX_WHEELS>,
    /// The tensioner on the idler.
    pub tensioner: Tensioner<T>,
    /// The ground under the road wheels, if the robot stands on it.
    pub ground: Option<Ground<T>>,
    /// Constant resisting torque of all bearings, referred to the drive
    /// axle, N·m (0: none).
    pub bearing_friction_nm: T,
    /// The contact law and the idler's slider.
    pub contact: WheelContact<T>,
}

impl<T: Real> RunningGear<T> {
    /// No wheels yet, the given tensioner, no ground, no bearing friction,
    /// the default contact law.
    pub fn new(tensioner: Tensioner<T>) -> Self {
        RunningGear {
            wheels: heapless::Vec::new(),
            tensioner,
            ground: None,
            bearing_friction_nm: T::ZERO,
            contact: WheelContact::default(),
        }
    }

    /// Add a wheel; more than [`MAX_WHEELS`] is a capacity error.
    ///
    /// ```
    /// use trackbelt::gear::{RunningGear, Tensioner, Wheel, WheelRole};
    /// let mut g = RunningGear::<f64>::new(Tensioner::FixedCentre);
    /// let w = Wheel { role: WheelRole::Road, x_m: 0.0, y_m: 0.0, diameter_m: 0.1 };
    /// for _ in 0..8 { g.push(w)?; }
    /// assert!(g.push(w).is_err());
    /// # Ok::<(), trackbelt::Error>(())
    /// ```
    pub fn push(&mut self, wheel: Wheel<T>) -> Result<()> {
        self.wheels.push(wheel).map_err(|_| Error::Capacity {
            what: "running-gear wheels",
            requested: MAX_WHEELS + 1,
            capacity: MAX_WHEELS,
        })
    }

    /// The paper's rig: a drive wheel at the origin and an idler at
    /// `(centre_distance_m, 0)` on a force tensioner, both from `config`
    /// (diameters, tensioner force, contact law, bearing friction).
    pub fn paper_rig(config: &RigConfig<T>, centre_distance_m: T) -> Result<Self> {
        let mut g = RunningGear::new(Tensioner::Force {
            force_n: config.idler_force_n,
        });
        g.push(Wheel {
            role: WheelRole::Drive,
            x_m: T::ZERO,
            y_m: T::ZERO,
            diameter_m: config.drive_diameter_m,
        })?;
        g.push(Wheel {
            role: WheelRole::Idler,
            x_m: centre_distance_m,
            y_m: T::ZERO,
            diameter_m: config.idler_diameter_m,
        })?;
        g.bearing_friction_nm = config.bearing_friction_nm;
        g.contact = WheelContact {
            stiffness_n_per_m: config.wheel_stiffness_n_per_m,
            damping_n_s_per_m: config.wheel_damping_n_s_per_m,
            drive_friction: config.drive_friction,
            slip_speed_m_s: config.slip_speed_m_s,
            idler_mass_kg: config.idler_mass_kg,
            idler_damping_n_s_per_m: config.idler_damping_n_s_per_m,
        };
        g.validate()?;
        Ok(g)
    }

    /// The drive wheel (`None` before one is added).
    pub fn drive(&self) -> Option<&Wheel<T>> {
        self.wheels.iter().find(|w| w.role == WheelRole::Drive)
    }

    /// The idler (`None` before one is added).
    pub fn idler(&self) -> Option<&Wheel<T>> {
        self.wheels.iter().find(|w| w.role == WheelRole::Idler)
    }

    /// How many wheels have `role`.
    pub fn count(&self, role: WheelRole) -> usize {
        self.wheels.iter().filter(|w| w.role == role).count()
    }

    /// When this is the two-wheel rig (drive and idler on one horizontal
    /// line, the idler ahead of the drive, a force tensioner, no ground):
    /// the [`RigConfig`] that simulates it. `None` otherwise.
    pub fn two_wheel_rig_config(&self) -> Option<RigConfig<T>> {
        let (d, i) = (self.drive()?, self.idler()?);
        let force_n = match self.tensioner {
            Tensioner::Force { force_n } => force_n,
            Tensioner::FixedCentre => return None,
        };
        if self.wheels.len() != 2 || self.ground.is_some() || d.y_m != i.y_m || i.x_m <= d.x_m {
            return None;
        }
        Some(RigConfig {
            drive_diameter_m: d.diameter_m,
            idler_diameter_m: i.diameter_m,
            idler_force_n: force_n,
            idler_mass_kg: self.contact.idler_mass_kg,
            idler_damping_n_s_per_m: self.contact.idler_damping_n_s_per_m,
            wheel_stiffness_n_per_m: self.contact.stiffness_n_per_m,
            wheel_damping_n_s_per_m: self.contact.damping_n_s_per_m,
            drive_friction: self.contact.drive_friction,
            slip_speed_m_s: self.contact.slip_speed_m_s,
            bearing_friction_nm: self.bearing_friction_nm,
        })
    }

    /// Check the running gear: one drive wheel, one idler, finite centres,
    /// positive diameters, wheels that do not overlap, road wheels only
    /// with ground (and ground only with road wheels), a positive
    /// tensioner force and load, a sane contact law.
    ///
    /// ```
    /// use trackbelt::gear::{RunningGear, Tensioner, Wheel, WheelRole};
    /// let mut g = RunningGear::<f64>::new(Tensioner::Force { force_n: 300.0 });
    /// g.push(Wheel { role: WheelRole::Drive, x_m: 0.0, y_m: 0.0, diameter_m: 0.2 })?;
    /// assert!(g.validate().is_err()); // no idler
    /// g.push(Wheel { role: WheelRole::Idler, x_m: 0.1, y_m: 0.0, diameter_m: 0.2 })?;
    /// assert!(g.validate().is_err()); // the wheels overlap
    /// # Ok::<(), trackbelt::Error>(())
    /// ```
    pub fn validate(&self) -> Result<()> {
        let pos = |x: T| x.is_finite() && x > T::ZERO;
        let nonneg = |x: T| x.is_finite() && x >= T::ZERO;
        if self.count(WheelRole::Drive) != 1 {
            return Err(invalid(
                "running_gear.wheels",
                "needs exactly one wheel with role \"drive\"",
            ));
        }
        if self.count(WheelRole::Idler) != 1 {
            return Err(invalid(
                "running_gear.wheels",
                "needs exactly one wheel with role \"idler\"",
            ));
        }
        for w in &self.wheels {
            if !(w.x_m.is_finite() && w.y_m.is_finite()) {
                return Err(invalid(
                    "running_gear.wheels.centre",
                    "must be finite (x_mm, y_mm)",
                ));
            }
            if !pos(w.diameter_m) {
                return Err(invalid(
                    "running_gear.wheels.diameter",
                    "must be finite and positive",
                ));
            }
        }
        for (k, a) in self.wheels.iter().enumerate() {
            for b in self.wheels.iter().skip(k + 1) {
                let (dx, dy) = (a.x_m - b.x_m, a.y_m - b.y_m);
                let r = (a.diameter_m + b.diameter_m) * T::from_f64(0.5);
                if dx * dx + dy * dy <= r * r {
                    return Err(invalid(
                        "running_gear.wheels",
                        "two wheels overlap: move their centres apart or make them smaller",
                    ));
                }
            }
        }
        let road = self.count(WheelRole::Road);
        match self.ground {
            Some(g) if !pos(g.load_kg) => {
                return Err(invalid(
                    "running_gear.ground.load_kg",
                    "must be finite and positive",
                ))
            }
            Some(_) if road == 0 => {
                return Err(invalid(
                    "running_gear.ground",
                    "ground needs at least one road wheel to press the belt onto it",
                ))
            }
            None if road > 0 => {
                return Err(invalid(
                    "running_gear.ground",
                    "road wheels need the ground (give [running_gear.ground] load_kg)",
                ))
            }
            _ => {}
        }
        if let Tensioner::Force { force_n } = self.tensioner {
            if !pos(force_n) {
                return Err(invalid(
                    "running_gear.tensioner.force_n",
                    "must be finite and positive",
                ));
            }
        }
        let c = &self.contact;
        let checks: [(&'static str, bool); 7] = [
            (
                "running_gear.bearing_friction_nm",
                nonneg(self.bearing_friction_nm),
            ),
            (
                "running_gear.contact.stiffness_n_per_m",
                pos(c.stiffness_n_per_m),
            ),
            (
                "running_gear.contact.damping_n_s_per_m",
                nonneg(c.damping_n_s_per_m),
            ),
            ("running_gear.contact.drive_friction", pos(c.drive_friction)),
            ("running_gear.contact.slip_speed_m_s", pos(c.slip_speed_m_s)),
            ("running_gear.contact.idler_mass_kg", pos(c.idler_mass_kg)),
            (
                "running_gear.contact.idler_damping_n_s_per_m",
                nonneg(c.idler_damping_n_s_per_m),
            ),
        ];
        for (field, ok) in checks {
            if !ok {
                return Err(invalid(
                    field,
                    "must be finite and positive (damping, bearing friction: not negative)",
                ));
            }
        }
        Ok(())
    }

    /// The same running gear in another number type.
    pub fn cast<U: Real>(&self) -> RunningGear<U> {
        let c = |x: T| U::from_f64(x.to_f64());
        let mut wheels = heapless::Vec::new();
        for w in &self.wheels {
            // Same capacity on both sides: cannot overflow.
            let _ = wheels.push(Wheel {
                role: w.role,
                x_m: c(w.x_m),
                y_m: c(w.y_m),
                diameter_m: c(w.diameter_m),
            });
        }
        RunningGear {
            wheels,
            tensioner: match self.tensioner {
                Tensioner::Force { force_n } => Tensioner::Force {
                    force_n: c(force_n),
                },
                Tensioner::FixedCentre => Tensioner::FixedCentre,
            },
            ground: self.ground.map(|g| Ground {
                load_kg: c(g.load_kg),
            }),
            bearing_friction_nm: c(self.bearing_friction_nm),
            contact: WheelContact {
                stiffness_n_per_m: c(self.contact.stiffness_n_per_m),
                damping_n_s_per_m: c(self.contact.damping_n_s_per_m),
                drive_friction: c(self.contact.drive_friction),
                slip_speed_m_s: c(self.contact.slip_speed_m_s),
                idler_mass_kg: c(self.contact.idler_mass_kg),
                idler_damping_n_s_per_m: c(self.contact.idler_damping_n_s_per_m),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn robot() -> RunningGear<f64> {
        let mut g = RunningGear::new(Tensioner::Force { force_n: 400.0 });
        for (role, x, y, d) in [
            (WheelRole::Drive, 0.0, 0.0, 0.16),
            (WheelRole::Idler, 0.52, 0.0, 0.14),
            (WheelRole::Road, 0.17, -0.06, 0.09),
            (WheelRole::Road, 0.35, -0.06, 0.09),
        ] {
            g.push(Wheel {
                role,
                x_m: x,
                y_m: y,
                diameter_m: d,
            })
            .unwrap();
        }
        g.ground = Some(Ground { load_kg: 12.0 });
        g
    }

    #[test]
    fn robot_is_valid_and_not_a_rig() {
        let g = robot();
        g.validate().unwrap();
        assert!(g.two_wheel_rig_config().is_none());
        assert_eq!(g.count(WheelRole::Road), 2);
    }

    #[test]
    fn paper_rig_round_trips_to_its_config() {
        let c = RigConfig::<f64> {
            bearing_friction_nm: 0.2,
            idler_diameter_m: 0.25,
            ..Default::default()
        };
        let g = RunningGear::paper_rig(&c, 0.74).unwrap();
        assert_eq!(g.two_wheel_rig_config(), Some(c));
        assert_eq!(g.cast::<f32>().cast::<f64>().wheels.len(), 2);
    }

    #[test]
    fn bad_gear_is_an_error() {
        let mut g = robot();
        g.ground = None;
        assert!(g.validate().is_err());
        let mut g = robot();
        g.wheels[2].diameter_m = f64::NAN;
        assert!(g.validate().is_err());
        let mut g = robot();
        g.tensioner = Tensioner::Force { force_n: -1.0 };
        assert!(g.validate().is_err());
        let mut g = robot();
        g.wheels[1].role = WheelRole::Drive;
        assert!(g.validate().is_err());
    }
}

//! `Serialize`/`Deserialize` for the types whose fields are not plain data
//! (feature `serde`).

use heapless::Vec;
use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::real::Real;
use crate::stiffness::{TorqueTable, TABLE_CAPACITY};

/// A torque table as written: its breakpoints. The segment slopes are
/// derived again on loading.
#[derive(Serialize, Deserialize)]
#[serde(rename = "TorqueTable")]
struct Breakpoints<A> {
    angle_rad: A,
    torque_nm: A,
}

/// Serialized as `{ angle_rad: [...], torque_nm: [...] }` (the breakpoints,
/// (0, 0) included).
impl<T: Real + Serialize> Serialize for TorqueTable<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        Breakpoints {
            angle_rad: self.angles_rad(),
            torque_nm: self.torques_nm(),
        }
        .serialize(s)
    }
}

/// Loaded through [`TorqueTable::new`]: validated, with (0, 0) inserted
/// when missing and the slopes computed.
impl<'de, T: Real + Deserialize<'de>> Deserialize<'de> for TorqueTable<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let b = Breakpoints::<Vec<T, TABLE_CAPACITY>>::deserialize(d)?;
        TorqueTable::new(&b.angle_rad, &b.torque_nm).map_err(D::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use crate::estimator::{EstimatorTable, Status, SPEED_POINTS};
    use crate::joint::JointLaw;
    use crate::params::{Method, Model, Variant};
    use crate::stiffness::{Stiffness, TorqueTable};

    #[test]
    fn params_round_trip_through_serde() {
        let model = Model::<f64>::paper(Variant::E56, Method::II).unwrap();
        let s = json(&model);
        let back: Model<f64> = serde_json::from_str(&s).unwrap();
        assert_eq!(back, model);

        let t = TorqueTable::<f64>::new(&[-0.6, -0.2, 0.1], &[-6.0, -1.0, 2.0]).unwrap();
        let law = JointLaw::new(Stiffness::Table(t), 0.2).unwrap();
        let s = json(&law);
        assert!(s.contains("\"angle_rad\":[-0.6,-0.2,0.0,0.1]"), "{s}");
        let back: JointLaw<f64> = serde_json::from_str(&s).unwrap();
        assert_eq!(back, law);
    }

    #[test]
    fn torque_table_is_validated_on_loading() {
        let bad = r#"{"angle_rad":[-0.2,-0.6],"torque_nm":[-1.0,-6.0]}"#;
        let e = serde_json::from_str::<TorqueTable<f64>>(bad).unwrap_err();
        assert!(e.to_string().contains("table"), "{e}");
    }

    #[test]
    fn estimator_table_and_status_round_trip() {
        let mut loss = [0.0; SPEED_POINTS];
        loss[3] = 0.25;
        let t = EstimatorTable::<f32>::from_coefficients(1.0, 1.0, loss, loss, 0.1, 0.02);
        let back: EstimatorTable<f32> = serde_json::from_str(&json(&t)).unwrap();
        assert_eq!(back, t);
        let s = Status::BAD_TICK | Status::SPEED_OUT_OF_RANGE;
        assert_eq!(json(&s), "\"BAD_TICK | SPEED_OUT_OF_RANGE\"");
    }

    fn json<T: serde::Serialize>(x: &T) -> String {
        serde_json::to_string(x).unwrap()
    }
}

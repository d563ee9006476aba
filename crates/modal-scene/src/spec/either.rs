//! Hand-written `Deserialize` for the scene's either-or values: a mesh file
//! path or a generator table, a material preset name or a constants table,
//! an axis-angle or an Euler rotation.
//!
//! serde's `untagged` enums tried each form in turn and, when none fitted,
//! replaced every inner error with one generic message: a misspelt key in a
//! generator or material table was reported without its name, and a
//! rotation (whose forms are not `deny_unknown_fields` structs) silently
//! ignored unknown keys (`units = "radians"`) or a second form (`euler`
//! next to `axis`). Here the form is chosen by the value's type, and each
//! table's own error travels up while `serde_path_to_error` records the key,
//! so these errors name their full key path like every other table's.

use std::fmt;
use std::path::PathBuf;

use serde::de::value::MapAccessDeserializer;
use serde::de::{self, DeserializeSeed, Deserializer, MapAccess, Visitor};
use serde::Deserialize;

use super::{ExplicitMaterial, MaterialSpec, MeshSource, RotationSpec};

/// The two forms of a rotation, for error messages.
const ROTATION_FORMS: &str = "a rotation is { axis = [x, y, z], angle = DEG } or { euler = [X, Y, Z] }";

impl<'de> Deserialize<'de> for MeshSource {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(NameOrTable {
            expecting: "a mesh file path or a generator table like { generate = \"box\", size = [..] }",
            from_name: |path| MeshSource::File(PathBuf::from(path)),
            from_table: MeshSource::Generate,
        })
    }
}

impl<'de> Deserialize<'de> for MaterialSpec {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(NameOrTable::<ExplicitMaterial, _> {
            expecting: "a material preset name or a table { youngs, poisson, density, alpha, beta }",
            from_name: |name| MaterialSpec::Preset(name.to_string()),
            from_table: MaterialSpec::Explicit,
        })
    }
}

/// Accepts a string (`from_name`) or a table read as `Table` (`from_table`),
/// whose errors, with their keys, pass through unchanged.
struct NameOrTable<Table, Out> {
    expecting: &'static str,
    from_name: fn(&str) -> Out,
    from_table: fn(Table) -> Out,
}

impl<'de, Table: Deserialize<'de>, Out> Visitor<'de> for NameOrTable<Table, Out> {
    type Value = Out;

    fn expecting(&self, formatter: &mut fmt::Formatter) -> fmt::Result {
        formatter.write_str(self.expecting)
    }

    fn visit_str<E: de::Error>(self, name: &str) -> Result<Out, E> {
        Ok((self.from_name)(name))
    }

    fn visit_map<A: MapAccess<'de>>(self, table: A) -> Result<Out, A::Error> {
        Table::deserialize(MapAccessDeserializer::new(table)).map(self.from_table)
    }
}

impl<'de> Deserialize<'de> for RotationSpec {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_map(RotationVisitor)
    }
}

/// Reads a rotation table key by key, so that a key that does not belong is
/// refused while its name is known.
struct RotationVisitor;

impl<'de> Visitor<'de> for RotationVisitor {
    type Value = RotationSpec;

    fn expecting(&self, formatter: &mut fmt::Formatter) -> fmt::Result {
        formatter.write_str("a rotation table { axis = [x, y, z], angle = DEG } or { euler = [X, Y, Z] }")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut table: A) -> Result<RotationSpec, A::Error> {
        let (mut axis, mut angle, mut euler) = (None, None, None);
        loop {
            let seed = RotationKeySeed {
                axis_angle_given: axis.is_some() || angle.is_some(),
                euler_given: euler.is_some(),
            };
            match table.next_key_seed(seed)? {
                Some(RotationKey::Axis) => axis = Some(table.next_value()?),
                Some(RotationKey::Angle) => angle = Some(table.next_value()?),
                Some(RotationKey::Euler) => euler = Some(table.next_value()?),
                None => break,
            }
        }
        let refuse = |why: &str| de::Error::custom(format!("{why}; {ROTATION_FORMS}"));
        match (axis, angle, euler) {
            (Some(axis), Some(angle), None) => Ok(RotationSpec::AxisAngle { axis, angle }),
            (None, None, Some(euler)) => Ok(RotationSpec::Euler { euler }),
            (Some(_), None, None) => Err(refuse("`axis` needs `angle`")),
            (None, Some(_), None) => Err(refuse("`angle` needs `axis`")),
            (None, None, None) => Err(refuse("empty table")),
            // The key seed refuses the second form as soon as it appears.
            _ => Err(refuse("give `axis` and `angle`, or `euler`, not both")),
        }
    }
}

/// A key of a rotation table.
#[derive(Clone, Copy)]
enum RotationKey {
    Axis,
    Angle,
    Euler,
}

/// Reads one key of a rotation table; an unknown key, or one of the form
/// other than the one already begun, is an error raised while reading the key
/// so that the error's path ends with it (`objects[0].rotation.units`).
struct RotationKeySeed {
    axis_angle_given: bool,
    euler_given: bool,
}

impl<'de> DeserializeSeed<'de> for RotationKeySeed {
    type Value = RotationKey;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<RotationKey, D::Error> {
        deserializer.deserialize_identifier(self)
    }
}

impl<'de> Visitor<'de> for RotationKeySeed {
    type Value = RotationKey;

    fn expecting(&self, formatter: &mut fmt::Formatter) -> fmt::Result {
        formatter.write_str("a rotation key: `axis`, `angle` or `euler`")
    }

    fn visit_str<E: de::Error>(self, key: &str) -> Result<RotationKey, E> {
        let parsed = match key {
            "axis" => RotationKey::Axis,
            "angle" => RotationKey::Angle,
            "euler" => RotationKey::Euler,
            _ => return Err(E::custom(format!("unknown key; {ROTATION_FORMS}"))),
        };
        let other_form = match parsed {
            RotationKey::Euler if self.axis_angle_given => "`axis` and `angle`",
            RotationKey::Axis | RotationKey::Angle if self.euler_given => "`euler`",
            _ => return Ok(parsed),
        };
        Err(E::custom(format!("`{key}` cannot be combined with {other_form}; {ROTATION_FORMS}")))
    }
}

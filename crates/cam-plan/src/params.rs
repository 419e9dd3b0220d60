//! Deserialising an operation kind's own keys from the job, with errors that name the key.

use crate::operation::OperationSpec;
use crate::PlanError;
use serde::de::DeserializeOwned;

/// Deserialises the kind's own keys of `spec` into `T` (which should use
/// `#[serde(deny_unknown_fields)]`). Errors name the operation and the key: for an unknown
/// key the key itself, for a wrong type or value the field serde names.
pub fn parse<T: DeserializeOwned>(spec: &OperationSpec) -> Result<T, PlanError> {
    let value = toml::Value::Table(spec.params.clone());
    value.try_into::<T>().map_err(|e| {
        let message = e.message().trim().to_string();
        let key = offending_key(&message).unwrap_or_else(|| "parameters".into());
        PlanError::param(&spec.name, key, message)
    })
}

/// The key a serde message is about: the first back-quoted word (`unknown field \`x\``,
/// `missing field \`y\``), if any.
pub fn offending_key(message: &str) -> Option<String> {
    let start = message.find('`')? + 1;
    let len = message[start..].find('`')?;
    Some(message[start..start + len].to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Process;
    use serde::Deserialize;

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct P {
        rows: usize,
        #[serde(default)]
        step_mm: Option<f64>,
    }

    fn spec(text: &str) -> OperationSpec {
        OperationSpec {
            name: "rough".into(),
            kind: "k".into(),
            tool: "t".into(),
            process: Process {
                spindle_rpm: 1.0,
                feed_per_tooth_mm: 1.0,
                plunge_feed_per_tooth_mm: None,
                depth_of_cut_mm: None,
                width_of_cut_mm: None,
                blade_allowance_mm: 0.0,
                hub_allowance_mm: 0.0,
                rapid_mm_per_min: 1.0,
            },
            params: toml::from_str(text).unwrap(),
        }
    }

    #[test]
    fn unknown_and_missing_keys_are_named() {
        let e = parse::<P>(&spec("rows = 3\nstepp_mm = 1.0\n")).unwrap_err();
        assert!(
            matches!(&e, PlanError::Param { key, .. } if key == "stepp_mm"),
            "{e}"
        );
        let e = parse::<P>(&spec("step_mm = 1.0\n")).unwrap_err();
        assert!(
            matches!(&e, PlanError::Param { key, .. } if key == "rows"),
            "{e}"
        );
        let e = parse::<P>(&spec("rows = \"x\"\n")).unwrap_err();
        assert!(e.to_string().contains("rough"), "{e}");
        assert!(parse::<P>(&spec("rows = 3\n")).is_ok());
    }
}

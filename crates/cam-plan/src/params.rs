//! Deserialising an operation kind's own keys from the job, with errors that name the key.

use crate::operation::OperationSpec;
use crate::PlanError;
use serde::de::DeserializeOwned;

/// Deserialises the kind's own keys of `spec` into `T` (which should use
/// `#[serde(deny_unknown_fields)]`). Errors name the operation and the key: for an unknown or
/// missing key the key serde names, for a wrong type or value the (dotted) key whose value it
/// is — found by deserialising the keys from their TOML text, where the error has a position.
pub fn parse<T: DeserializeOwned>(spec: &OperationSpec) -> Result<T, PlanError> {
    let text = match toml::to_string(&spec.params) {
        Ok(t) => t,
        Err(_) => return parse_value(spec),
    };
    toml::from_str::<T>(&text).map_err(|e| {
        let message = e.message().trim().to_string();
        let at = e.span().map(|s| s.start);
        // Only field messages quote a key; others (`invalid type: boolean \`true\``) quote
        // the value, and the key is the one at the error's position.
        let key = match (field_key(&message), at) {
            (Some(k), Some(at)) => match section_at(&text, at) {
                Some(s) if s != k => format!("{s}.{k}"),
                _ => k,
            },
            (Some(k), None) => k,
            (None, Some(at)) => key_at(&text, at).unwrap_or_else(|| "parameters".into()),
            (None, None) => "parameters".into(),
        };
        PlanError::param(&spec.name, key, message)
    })
}

/// The `[section]` of TOML `text` that byte `offset` lies in (the header's own line counts).
fn section_at(text: &str, offset: usize) -> Option<String> {
    let offset = offset.min(text.len());
    let line_end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    text[..line_end]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('[') && !l.starts_with("[["))
        .map(|l| l.trim_matches(|c| c == '[' || c == ']').trim().to_string())
}

/// [`parse`] from the TOML value directly (keys named only when serde names them).
fn parse_value<T: DeserializeOwned>(spec: &OperationSpec) -> Result<T, PlanError> {
    let value = toml::Value::Table(spec.params.clone());
    value.try_into::<T>().map_err(|e| {
        let message = e.message().trim().to_string();
        let key = offending_key(&message).unwrap_or_else(|| "parameters".into());
        PlanError::param(&spec.name, key, message)
    })
}

/// The dotted key whose value holds byte `offset` of TOML `text`: the last `name =` before
/// the offset on its line (an inline table's key where there is one), prefixed by the
/// `[section]` the line is in.
fn key_at(text: &str, offset: usize) -> Option<String> {
    let offset = offset.min(text.len());
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let before = &text[line_start..offset];
    let line = text[line_start..].lines().next().unwrap_or("");
    let trimmed = line.trim();
    if trimmed.starts_with('[') {
        return Some(
            trimmed
                .trim_matches(|c| c == '[' || c == ']')
                .trim()
                .to_string(),
        );
    }
    let eq = before.rfind('=')?;
    let name: String = before[..eq]
        .trim_end()
        .chars()
        .rev()
        .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == '-' || *c == '"')
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .filter(|c| *c != '"')
        .collect();
    if name.is_empty() {
        return None;
    }
    Some(match section_at(text, line_start) {
        Some(s) => format!("{s}.{name}"),
        None => name,
    })
}

/// The key a serde field message names (`unknown field \`x\``, `missing field \`y\``,
/// `duplicate field \`z\``); `None` for other messages, which quote values, not keys
/// (`invalid type: boolean \`true\``).
pub fn field_key(message: &str) -> Option<String> {
    ["unknown field", "missing field", "duplicate field"]
        .iter()
        .any(|m| message.starts_with(m))
        .then(|| offending_key(message))
        .flatten()
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
        #[serde(default)]
        level: Option<Level>,
    }

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Level {
        depth_mm: f64,
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
        assert!(
            matches!(&e, PlanError::Param { key, .. } if key == "rows"),
            "{e}"
        );
        let e = parse::<P>(&spec("rows = 3\nstep_mm = true\n")).unwrap_err();
        assert!(
            matches!(&e, PlanError::Param { key, .. } if key == "step_mm"),
            "{e}"
        );
        assert!(parse::<P>(&spec("rows = 3\n")).is_ok());
        // Nested tables: the dotted key.
        let e = parse::<P>(&spec("rows = 3\n[level]\ndepth_mm = \"x\"\n")).unwrap_err();
        assert!(
            matches!(&e, PlanError::Param { key, .. } if key == "level.depth_mm"),
            "{e}"
        );
        let e = parse::<P>(&spec("rows = 3\n[level]\ndepth_mm = 1.0\nstep = 2\n")).unwrap_err();
        assert!(
            matches!(&e, PlanError::Param { key, .. } if key == "level.step"),
            "{e}"
        );
        let e = parse::<P>(&spec("rows = 3\nlevel = { depth_mm = false }\n")).unwrap_err();
        assert!(
            matches!(&e, PlanError::Param { key, .. } if key == "level.depth_mm"),
            "{e}"
        );
    }
}

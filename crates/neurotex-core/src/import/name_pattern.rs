//! File-name patterns (`--pattern`): a recording's label and conditions read from its file
//! name.

use std::collections::BTreeMap;
use std::path::Path;
use std::str::FromStr;

use crate::error::{ParamError, Result};
use crate::recording::Meta;

use super::invalid;

/// A file-name pattern such as `{label}_F{force}_V{speed}mmps_{trial}.csv`: literal text and
/// `{field}`s. `label`, `speed` (mm/s), `force` (N) and `trial` fill the manifest's columns;
/// any other field becomes an extra manifest column. Text outside the fields is matched
/// literally (brackets, parentheses and dots included), in time linear in the name's
/// length: the pattern becomes a regular expression of the `regex` crate, which never
/// backtracks.
#[derive(Debug, Clone)]
pub struct NamePattern {
    parts: Vec<Part>,
    /// The fields in order: capture group `k + 1` holds field `k`.
    fields: Vec<String>,
    regex: regex::Regex,
}

impl PartialEq for NamePattern {
    fn eq(&self, other: &Self) -> bool {
        self.parts == other.parts
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Part {
    Literal(String),
    Field(String),
}

/// What a field's value looks like: `speed` and `force` are numbers, `trial` an integer,
/// anything else at least one character, as few as possible.
fn field_regex(field: &str) -> &'static str {
    match field {
        "speed" | "force" => r"([+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)",
        "trial" => r"([+-]?[0-9]+)",
        _ => r"(.+?)",
    }
}

impl NamePattern {
    /// Parses a pattern.
    ///
    /// # Errors
    /// Unbalanced braces, an empty field name, a field named twice, two fields with nothing
    /// between them, or a pattern too long to compile.
    pub fn parse(pattern: &str) -> Result<Self, ParamError> {
        let bad = |rule| ParamError::new("name-pattern", rule, pattern);
        let parts = split_pattern(pattern)?;
        let mut fields: Vec<String> = Vec::new();
        let mut source = String::from(r"(?s)\A");
        for part in &parts {
            match part {
                Part::Literal(text) => source.push_str(&regex::escape(text)),
                Part::Field(name) => {
                    if fields.contains(name) {
                        return Err(bad("each field may appear once"));
                    }
                    fields.push(name.clone());
                    source.push_str(field_regex(name));
                }
            }
        }
        if fields.is_empty() {
            return Err(bad("the pattern names no {field}"));
        }
        source.push_str(r"\z");
        let regex = regex::Regex::new(&source).map_err(|_| bad("the pattern is too long"))?;
        Ok(NamePattern {
            parts,
            fields,
            regex,
        })
    }

    /// The pattern as written: literal text and `{field}`s.
    pub fn text(&self) -> String {
        self.parts
            .iter()
            .map(|part| match part {
                Part::Literal(text) => text.clone(),
                Part::Field(name) => format!("{{{name}}}"),
            })
            .collect()
    }

    /// The fields of `name`, or `None` when it does not match. Fields match as few
    /// characters as possible (at least one) such that the rest still matches; `speed` and
    /// `force` only match numbers and `trial` only integers, so a label may contain the
    /// pattern's separators (`Denim_Flex_F150_...`).
    pub fn matches(&self, name: &str) -> Option<BTreeMap<String, String>> {
        let caps = self.regex.captures(name)?;
        let fields = self.fields.iter().enumerate();
        Some(
            fields
                .map(|(k, field)| (field.clone(), caps[k + 1].to_string()))
                .collect(),
        )
    }
}

/// A pattern's literal text and `{field}`s, in order.
fn split_pattern(pattern: &str) -> Result<Vec<Part>, ParamError> {
    let bad = |rule| ParamError::new("name-pattern", rule, pattern);
    let mut parts = Vec::new();
    let mut rest = pattern;
    while !rest.is_empty() {
        let literal_end = rest.find('{').unwrap_or(rest.len());
        if literal_end > 0 {
            if rest[..literal_end].contains('}') {
                return Err(bad("a `}` without its `{`"));
            }
            parts.push(Part::Literal(rest[..literal_end].to_string()));
            rest = &rest[literal_end..];
            continue;
        }
        let end = rest
            .find('}')
            .ok_or_else(|| bad("every `{` needs a closing `}`"))?;
        let name = &rest[1..end];
        if name.is_empty() || name.contains('{') {
            return Err(bad("fields are written {name}, with a non-empty name"));
        }
        if matches!(parts.last(), Some(Part::Field(_))) {
            return Err(bad("two fields need literal text between them"));
        }
        parts.push(Part::Field(name.to_string()));
        rest = &rest[end + 1..];
    }
    Ok(parts)
}

impl FromStr for NamePattern {
    type Err = ParamError;

    /// As [`NamePattern::parse`].
    fn from_str(pattern: &str) -> Result<Self, ParamError> {
        NamePattern::parse(pattern)
    }
}

pub(crate) fn meta_from_name(path: &Path, pattern: Option<&NamePattern>) -> Result<Meta> {
    // A lossy name would turn distinct non-UTF-8 names (and the labels in them) into one.
    let name = match path.file_name().map(|n| n.to_str()) {
        Some(Some(name)) => name.to_string(),
        Some(None) => {
            let message = "the file name is not valid UTF-8, so neither it nor a label taken from it can be written into the manifest; rename the file";
            return Err(invalid(path, message));
        }
        None => String::new(),
    };
    let mut meta = Meta {
        file: name.clone(),
        ..Meta::default()
    };
    let Some(pattern) = pattern else {
        meta.label = Path::new(&name)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_default()
            .to_string();
        return Ok(meta);
    };
    let fields = pattern
        .matches(&name)
        .ok_or_else(|| {
            let message = format!(
                "the file name does not match --name-pattern `{}` (text outside {{fields}} must match exactly, case included)",
                pattern.text()
            );
            invalid(path, message)
        })?;
    for (key, value) in fields {
        let number = |what: &str| -> Result<f64> {
            value
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    invalid(
                        path,
                        format!("field {{{key}}} of the file name must be {what}, got `{value}`"),
                    )
                })
        };
        match key.as_str() {
            "label" => meta.label = value.clone(),
            "speed" => meta.speed_mm_s = Some(number("a number of mm/s")?),
            "force" => meta.force_n = Some(number("a number")?),
            "trial" => {
                meta.trial = Some(value.parse().map_err(|_| {
                    invalid(
                        path,
                        format!(
                            "field {{trial}} of the file name must be an integer, got `{value}`"
                        ),
                    )
                })?)
            }
            _ => {
                meta.extra.insert(key, value);
            }
        }
    }
    if meta.label.is_empty() {
        return Err(invalid(path, "the pattern gives no {label}"));
    }
    Ok(meta)
}

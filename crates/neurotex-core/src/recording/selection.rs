//! Selecting a dataset's recordings by a manifest column's value (`--where speed_mm_s=5`).

use std::fmt;
use std::str::FromStr;

use crate::error::{DatasetError, ParamError, Result};
use crate::values::Speed;

use super::{Meta, MANIFEST_COLUMNS, NUMERIC_COLUMNS};

/// Recordings whose manifest column holds one of some values, written `COLUMN=V1,V2`:
/// numeric columns ([`NUMERIC_COLUMNS`]) compare as numbers (`5` is `5.0`), every other
/// column as text. Any column but `label` (selecting classes leaves the test set with
/// classes never trained on).
#[derive(Debug, Clone, PartialEq)]
pub struct Selection {
    /// The manifest column.
    pub column: String,
    /// The values, as written.
    pub values: Vec<String>,
}

impl Selection {
    /// The recordings at `speeds`.
    pub fn speeds(speeds: &[Speed]) -> Self {
        Selection {
            column: "speed_mm_s".into(),
            values: speeds.iter().map(Speed::to_string).collect(),
        }
    }

    fn numeric(&self) -> bool {
        NUMERIC_COLUMNS.contains(&self.column.as_str())
    }

    /// Whether `field` (a recording's value in the column) is `value`.
    fn same(&self, field: &str, value: &str) -> bool {
        if self.numeric() {
            matches!((field.parse::<f64>(), value.parse::<f64>()), (Ok(a), Ok(b)) if a == b)
        } else {
            field == value
        }
    }

    /// The indices of `metas` selected, in order.
    ///
    /// # Errors
    /// [`DatasetError::NoColumn`] when no recording has a value in the column,
    /// [`DatasetError::NoRecordingsWhere`] for the first value no recording has, naming
    /// the values present.
    pub fn rows(&self, metas: &[Meta]) -> Result<Vec<usize>> {
        let fields: Vec<Option<String>> = metas.iter().map(|m| m.field(&self.column)).collect();
        let mut present: Vec<&str> = fields.iter().flatten().map(String::as_str).collect();
        if present.is_empty() {
            let mut columns: Vec<String> = MANIFEST_COLUMNS.map(String::from).to_vec();
            let others = NUMERIC_COLUMNS.iter().map(|c| c.to_string());
            let others = others.chain(metas.iter().flat_map(|m| m.extra.keys().cloned()));
            for c in others {
                if !columns.contains(&c) && metas.iter().any(|m| m.field(&c).is_some()) {
                    columns.push(c);
                }
            }
            let column = self.column.clone();
            return Err(DatasetError::NoColumn { column, columns }.into());
        }
        if let Some(value) = self
            .values
            .iter()
            .find(|v| !present.iter().any(|f| self.same(f, v)))
        {
            if self.numeric() {
                present.sort_by(|a, b| {
                    a.parse::<f64>()
                        .unwrap_or(0.0)
                        .total_cmp(&b.parse().unwrap_or(0.0))
                });
            } else {
                present.sort();
            }
            present.dedup();
            return Err(DatasetError::NoRecordingsWhere {
                column: self.column.clone(),
                value: value.clone(),
                present: present.into_iter().map(String::from).collect(),
            }
            .into());
        }
        let chosen = |f: &Option<String>| {
            f.as_deref()
                .is_some_and(|f| self.values.iter().any(|v| self.same(f, v)))
        };
        Ok((0..metas.len()).filter(|&i| chosen(&fields[i])).collect())
    }
}

impl fmt::Display for Selection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}={}", self.column, self.values.join(","))
    }
}

impl FromStr for Selection {
    type Err = ParamError;

    /// Parses `COLUMN=V1,V2,...`; values of numeric columns must be numbers.
    fn from_str(text: &str) -> Result<Self, ParamError> {
        let rule = "a selection is COLUMN=VALUE[,VALUE...] over a manifest column other than label, numbers in numeric columns";
        let bad = || ParamError::new("where", rule, text);
        let (column, values) = text.split_once('=').ok_or_else(bad)?;
        let column = column.trim().to_string();
        let values: Vec<String> = values.split(',').map(|v| v.trim().to_string()).collect();
        if column.is_empty() || column == "label" || values.iter().any(String::is_empty) {
            return Err(bad());
        }
        let selection = Selection { column, values };
        let number = |v: &String| v.parse::<f64>().is_ok_and(f64::is_finite);
        if selection.numeric() && !selection.values.iter().all(number) {
            return Err(bad());
        }
        Ok(selection)
    }
}

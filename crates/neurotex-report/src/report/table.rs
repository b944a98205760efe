//! A small builder for markdown tables, so every table of the report has a header, a rule
//! and rows of the same width.

use std::fmt::Display;

/// A markdown table being built row by row.
#[derive(Debug, Clone, Default)]
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

/// A cell's text with the characters that would break a markdown table escaped, and
/// HTML's (labels and file names come from the user's data: `<b>` must show as text).
fn cell(text: &str) -> String {
    escape_html(text).replace('|', "\\|").replace('\n', " ")
}

/// `text` with `&`, `<` and `>` escaped, so that a renderer shows it as written.
pub(crate) fn escape_html(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

impl Table {
    /// A table with these column headings.
    pub fn new<I, S>(header: I) -> Self
    where
        I: IntoIterator<Item = S>,
        S: Display,
    {
        Table {
            header: header.into_iter().map(|h| cell(&h.to_string())).collect(),
            rows: Vec::new(),
        }
    }

    /// Adds a row; a short row is padded with empty cells and a long one is cut to the
    /// header's width, so the table stays rectangular.
    pub fn row<I, S>(&mut self, cells: I) -> &mut Self
    where
        I: IntoIterator<Item = S>,
        S: Display,
    {
        let mut row: Vec<String> = cells
            .into_iter()
            .map(|c| cell(&c.to_string()))
            .take(self.header.len())
            .collect();
        row.resize(self.header.len(), String::new());
        self.rows.push(row);
        self
    }

    /// Whether no row was added.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The table as markdown, ending in a newline.
    pub fn render(&self) -> String {
        let line = |cells: &[String]| format!("| {} |\n", cells.join(" | "));
        let mut out = line(&self.header);
        out.push_str(&format!("|{}\n", "---|".repeat(self.header.len())));
        for row in &self.rows {
            out.push_str(&line(row));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_padded_cut_and_escaped() {
        let mut t = Table::new(["a", "b"]);
        assert!(t.is_empty());
        t.row(["1"]).row(["x|y", "2", "dropped"]);
        assert_eq!(
            t.render(),
            "| a | b |\n|---|---|\n| 1 |  |\n| x\\|y | 2 |\n"
        );
        let mut t = Table::new(["label"]);
        t.row(["<img src=x onerror=alert(1)> & co"]);
        assert_eq!(
            t.render(),
            "| label |\n|---|\n| &lt;img src=x onerror=alert(1)&gt; &amp; co |\n"
        );
    }
}

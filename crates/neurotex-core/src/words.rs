//! Parser messages in a user's words: serde's, the standard library's number parsing's,
//! and TOML's and JSON's errors with their line, each saying what the file was expected to
//! hold rather than the parser's type names; signed differences as reports print them;
//! counts with their nouns.

/// A difference with its sign and one decimal (`+12.3`, `-0.4`), and `0.0` for one that
/// rounds to zero, never `-0.0` or `+0.0`: a difference of accuracies in points, as the
/// reports print them.
pub fn signed_one_decimal(x: f64) -> String {
    let text = format!("{x:+.1}");
    match text.as_str() {
        "+0.0" | "-0.0" => "0.0".to_string(),
        _ => text,
    }
}

/// A count with its noun, singular for one (`1 cell`, `7 cells`, `0 repeats`): the noun
/// takes a plain `s` in the plural.
pub fn counted(n: usize, noun: &str) -> String {
    match n {
        1 => format!("1 {noun}"),
        _ => format!("{n} {noun}s"),
    }
}

/// A serde parser's message in a user's words: its type names and jargon turned into
/// what the file was expected to hold ("invalid type: string \"min\", expected internally
/// tagged enum Baseline" becomes "a string \"min\" where a Baseline table was expected").
pub fn parser_words(message: &str) -> String {
    let message = message.trim().trim_end_matches('.');
    let stated = message
        .strip_prefix("invalid type: ")
        .or_else(|| message.strip_prefix("invalid value: "));
    let (found, expected) = match stated {
        Some(rest) => match rest.split_once(", expected ") {
            Some((found, expected)) => (Some(found), expected),
            None => (None, rest),
        },
        None => (None, message),
    };
    let expected = expected
        .replace("internally tagged enum ", "")
        .replace("struct ", "")
        .replace("enum ", "")
        .replace("a sequence", "a list")
        .replace("a map", "a table");
    // Rust's number types, as the value each may hold.
    let expected = match expected.as_str() {
        "usize" | "u64" | "u32" | "u16" | "u8" => "a whole number, 0 or more".to_string(),
        "isize" | "i64" | "i32" | "i16" | "i8" => "a whole number".to_string(),
        "f64" | "f32" => "a number".to_string(),
        _ => expected,
    };
    match found {
        Some(found) => {
            let found = found
                .replace("map", "a table")
                .replace("sequence", "a list");
            format!("{found} where {expected} was expected")
        }
        None => expected,
    }
}

/// The standard library's number parse errors ("invalid digit found in string") in a
/// user's words, what was expected; other text unchanged.
pub fn number_words(message: &str) -> String {
    message
        .replace(
            "invalid digit found in string",
            "expected a whole number such as 0, 1, 2 (no sign, point or letters)",
        )
        .replace(
            "cannot parse integer from empty string",
            "empty where a whole number was expected",
        )
        .replace(
            "number too large to fit in target type",
            "a whole number too large",
        )
        .replace("invalid float literal", "not a number")
}

/// A TOML file's error: where it is, the line as written, and what was wrong in
/// [`parser_words`], never the parser's own layout of it.
pub fn toml_error(text: &str, e: &toml::de::Error) -> String {
    let Some(span) = e.span() else {
        return parser_words(e.message());
    };
    let start = span.start.min(text.len());
    let line = text[..start].matches('\n').count() + 1;
    let line_text = text.lines().nth(line - 1).unwrap_or("").trim();
    let shown: String = line_text.chars().take(80).collect();
    format!("line {line} (`{shown}`): {}", parser_words(e.message()))
}

/// A JSON file's error: its line and column and what was wrong in [`parser_words`].
pub fn json_error(e: &serde_json::Error) -> String {
    let text = e.to_string();
    let message = text.split(" at line ").next().unwrap_or(&text);
    match e.line() {
        0 => parser_words(message),
        line => format!(
            "line {line}, column {}: {}",
            e.column(),
            parser_words(message)
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::{counted, signed_one_decimal};

    #[test]
    fn a_count_takes_its_noun_in_the_singular_for_one_only() {
        let said = [0, 1, 2, 7].map(|n| counted(n, "cell"));
        assert_eq!(said, ["0 cells", "1 cell", "2 cells", "7 cells"]);
    }

    #[test]
    fn a_difference_that_rounds_to_zero_has_no_sign() {
        assert_eq!(signed_one_decimal(12.34), "+12.3");
        assert_eq!(signed_one_decimal(-0.44), "-0.4");
        assert_eq!(signed_one_decimal(-0.04), "0.0");
        assert_eq!(signed_one_decimal(-0.0), "0.0");
        assert_eq!(signed_one_decimal(0.0), "0.0");
        assert_eq!(signed_one_decimal(0.05), "+0.1");
    }
}

//! Scene TOML as people read it. The `toml` crate writes every float in positional notation, so 1e-300
//! becomes a 300-digit decimal and 1e-10 `0.0000000001`. That text is the stored scene of every file
//! (`coin-log` metadata) and must stay as it is; what is printed for people (`record --dry-run`, `info
//! --scene`, `scenes --show`) goes through [`readable_toml`], which writes each float in the shortest form
//! that reads back to the same double, so the printed scene is still the same scene.

/// `text` (TOML as the `toml` crate writes it: one `key = value` per line) with every float of every value
/// written as `float_literal` does; strings, keys, comments and table headers are kept as they are.
#[must_use]
pub fn readable_toml(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.split_inclusive('\n') {
        let value = (!line.starts_with(['#', '[', '"', '\'']))
            .then(|| line.find(" = "))
            .flatten();
        match value {
            Some(at) => {
                out.push_str(&line[..at + 3]);
                rewrite_value(&line[at + 3..], &mut out);
            }
            None => out.push_str(line),
        }
    }
    out
}

/// A float as a TOML literal: [`Short`], with `.0` where that is a whole number without exponent (`100.0`).
fn float_literal(x: f64) -> String {
    let text = Short(x).to_string();
    if x.is_finite() && !text.contains(['.', 'e']) {
        format!("{text}.0")
    } else {
        text
    }
}

/// A number in messages: `{}` between 1e-4 and 1e16 (`0.5`, `100`), the shortest exponent form outside
/// (`1e-10`, `5e159`: `{}` writes 5e159 as 160 digits); either reads back to the same double.
#[derive(Debug, Clone, Copy)]
pub struct Short(pub f64);

impl std::fmt::Display for Short {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let x = self.0;
        if x.is_finite() && x != 0.0 && !(1e-4..1e16).contains(&x.abs()) {
            f.write_str(ryu::Buffer::new().format_finite(x))
        } else {
            write!(f, "{x}")
        }
    }
}

/// Copies a value (a number, string, array or inline table), rewriting its floats.
fn rewrite_value(value: &str, out: &mut String) {
    let bare = |c: char| c.is_ascii_alphanumeric() || "+-_.".contains(c);
    let mut rest = value;
    while let Some(c) = rest.chars().next() {
        let taken = match c {
            '"' | '\'' => string_len(rest, c),
            c if bare(c) => {
                let len = rest.find(|c: char| !bare(c)).unwrap_or(rest.len());
                let word = &rest[..len];
                let is_float = c.is_ascii_digit() || "+-".contains(c);
                match word.parse::<f64>() {
                    Ok(x) if is_float && word.contains(['.', 'e', 'E']) => {
                        out.push_str(&float_literal(x))
                    }
                    _ => out.push_str(word),
                }
                rest = &rest[len..];
                continue;
            }
            c => c.len_utf8(),
        };
        out.push_str(&rest[..taken]);
        rest = &rest[taken..];
    }
}

/// The length of the string literal that `text` starts with (quote `quote`), escapes included; the rest of
/// the text if it is not closed.
fn string_len(text: &str, quote: char) -> usize {
    let mut escaped = false;
    for (i, c) in text.char_indices().skip(1) {
        match c {
            '\\' if quote == '"' && !escaped => escaped = true,
            c if c == quote && !escaped => return i + 1,
            _ => escaped = false,
        }
    }
    text.len()
}

#[cfg(test)]
mod tests {
    use super::{float_literal, readable_toml};

    #[test]
    fn floats_print_short_and_strings_stay_as_written() {
        let text =
            "description = \"rtol = 0.0000000001, \\\"0.5\\\"\"\n[run]\nrtol = 0.0000000001\n\
                    omega = [0.0, -0.000000000000000000000000000000000000001, 2.5]\n\
                    dissipation = { model = \"power-law\", m = 2.0, coefficient = 0.00000001 }\n\
                    steps = 10\n";
        assert_eq!(
            readable_toml(text),
            "description = \"rtol = 0.0000000001, \\\"0.5\\\"\"\n[run]\nrtol = 1e-10\n\
             omega = [0.0, -1e-39, 2.5]\n\
             dissipation = { model = \"power-law\", m = 2.0, coefficient = 1e-8 }\nsteps = 10\n"
        );
        assert_eq!(float_literal(1e-300), "1e-300");
        assert_eq!(float_literal(100.0), "100.0");
        assert_eq!(float_literal(1e16), "1e16");
        assert_eq!(float_literal(-0.0), "-0.0");
    }
}

//! CSV as every table of coin-log is written (`export`, `analyse map`, the benchmarks): RFC 4180's quoting
//! (a field holding a comma, a double quote, a CR or an LF is quoted, its quotes doubled), LF line ends, and
//! numbers in their shortest round-trip form. A small helper rather than the `csv` crate: export streams
//! millions of rows through one reused line, where the crate would add a row type per table.

use std::borrow::Cow;

/// `text` as one CSV field, quoted when it must be.
#[must_use]
pub fn field(text: &str) -> Cow<'_, str> {
    if text.contains([',', '"', '\r', '\n']) {
        Cow::Owned(format!("\"{}\"", text.replace('"', "\"\"")))
    } else {
        Cow::Borrowed(text)
    }
}

/// One line of text fields, each by [`field`], ended by LF.
#[must_use]
pub fn record<S: AsRef<str>>(fields: &[S]) -> String {
    let mut line = Line::default();
    for f in fields {
        line.text(f.as_ref());
    }
    line.finish().to_string()
}

/// One line of text fields, each by [`field`], without its line end.
#[must_use]
pub fn line<S: AsRef<str>>(fields: &[S]) -> String {
    let mut line = record(fields);
    line.pop();
    line
}

/// The fields of one CSV line (RFC 4180), or `None` when a quote is not closed or is followed by
/// something other than a comma.
#[must_use]
pub fn split(line: &str) -> Option<Vec<String>> {
    let mut fields = Vec::new();
    let mut chars = line.chars().peekable();
    loop {
        let mut field = String::new();
        if chars.next_if_eq(&'"').is_some() {
            loop {
                match chars.next()? {
                    '"' if chars.next_if_eq(&'"').is_some() => field.push('"'),
                    '"' => break,
                    c => field.push(c),
                }
            }
            if !matches!(chars.peek(), None | Some(',')) {
                return None;
            }
        } else {
            while let Some(c) = chars.next_if(|&c| c != ',') {
                field.push(c);
            }
        }
        fields.push(field);
        if chars.next().is_none() {
            return Some(fields);
        }
    }
}

/// CSV being built field by field: one line reused from line to line (clear it after writing it out), or
/// a whole table (finish each line and go on).
#[derive(Default)]
pub struct Line {
    text: String,
    fields: usize,
    number: ryu::Buffer,
}

impl Line {
    fn separate(&mut self) {
        if self.fields > 0 {
            self.text.push(',');
        }
        self.fields += 1;
    }

    /// Appends a text field.
    pub fn text(&mut self, text: &str) -> &mut Self {
        self.separate();
        self.text.push_str(&field(text));
        self
    }

    /// Appends a number in its shortest round-trip form (`0.1`, `1e-300`, `1.0`).
    pub fn number(&mut self, x: f64) -> &mut Self {
        self.separate();
        self.text.push_str(self.number.format(x));
        self
    }

    /// Appends an empty field.
    pub fn empty(&mut self) -> &mut Self {
        self.separate();
        self
    }

    /// Ends the line; returns the buffer, the line with its LF last. The next field starts a new line.
    pub fn finish(&mut self) -> &str {
        self.text.push('\n');
        self.fields = 0;
        &self.text
    }

    /// Empties the buffer for the next line (after [`Line::finish`] was written out).
    pub fn clear(&mut self) {
        self.text.clear();
        self.fields = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::{field, line, record, split, Line};

    #[test]
    fn fields_are_quoted_by_one_rule_on_commas_quotes_cr_and_lf() {
        assert_eq!(field("coin"), "coin");
        assert_eq!(field(""), "");
        assert_eq!(field("a,b"), "\"a,b\"");
        assert_eq!(field("say \"hi\""), "\"say \"\"hi\"\"\"");
        assert_eq!(field("a\rb"), "\"a\rb\"");
        assert_eq!(field("a\nb"), "\"a\nb\"");
        assert_eq!(field("a b;c\t"), "a b;c\t", "nothing else is quoted");
        assert_eq!(record(&["t", "x,y", "\""]), "t,\"x,y\",\"\"\"\"\n");
    }

    #[test]
    fn a_line_mixes_numbers_text_and_empty_fields() {
        let mut line = Line::default();
        line.number(0.1)
            .text("a,b")
            .empty()
            .number(1e-300)
            .number(2.0);
        assert_eq!(line.finish(), "0.1,\"a,b\",,1e-300,2.0\n");
        line.clear();
        line.number(-0.0);
        assert_eq!(line.finish(), "-0.0\n");
    }

    #[test]
    fn fields_round_trip_through_csv_quoting() {
        let fields = ["1", "a,b", "say \"hi\"", "", "[0.0, 0.2]", "x"];
        let line = line(&fields);
        assert_eq!(line, "1,\"a,b\",\"say \"\"hi\"\"\",,\"[0.0, 0.2]\",x");
        assert_eq!(split(&line).unwrap(), fields);
        assert_eq!(split("").unwrap(), [""]);
        assert!(split("1,\"open").is_none());
        assert!(split("1,\"a\"b").is_none());
    }
}

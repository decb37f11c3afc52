//! Text recordings as labs save them: the separator (comma, semicolon, tab or spaces) and
//! the decimal mark (a decimal comma goes with a semicolon, tab or space separator) are
//! found from the first line that has any, and the text is rewritten as plain CSV line
//! for line (so file line numbers stay right, CRLF or not).

/// How the fields of a text recording are separated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Dialect {
    /// Plain CSV: comma-separated, decimal point.
    #[default]
    Comma,
    Semicolon,
    Tab,
    /// One or more spaces.
    Space,
}

impl Dialect {
    /// The separator in words, for messages.
    pub fn describe(self) -> &'static str {
        match self {
            Self::Comma => "comma-separated",
            Self::Semicolon => "semicolon-separated",
            Self::Tab => "tab-separated",
            Self::Space => "space-separated",
        }
    }

    /// The dialect of `text`, judged on its first non-blank line.
    pub fn sniff(text: &str) -> Self {
        let Some(line) = text.lines().map(|l| l.trim()).find(|l| !l.is_empty()) else { return Self::Comma };
        if line.contains(';') {
            Self::Semicolon
        } else if line.contains('\t') {
            Self::Tab
        } else if line.contains(',') {
            Self::Comma
        } else if line.split_whitespace().nth(1).is_some() {
            Self::Space
        } else {
            Self::Comma
        }
    }
}

/// `text` in `dialect` rewritten as CSV, one output line per input line; decimal commas
/// become points (any comma inside a field, since commas do not separate in these dialects).
pub fn to_csv(text: &str, dialect: Dialect) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let fields: Vec<&str> = match dialect {
            Dialect::Comma => vec![line],
            Dialect::Semicolon => line.split(';').collect(),
            Dialect::Tab => line.split('\t').collect(),
            Dialect::Space => line.split_whitespace().collect(),
        };
        for (i, f) in fields.iter().enumerate() {
            if i > 0 {
                out.push(',');
            }
            if dialect == Dialect::Comma {
                out.push_str(f);
            } else {
                out.extend(f.trim().chars().map(|c| if c == ',' { '.' } else { c }));
            }
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_separator_and_keeps_lines() {
        assert_eq!(Dialect::sniff("t;b\n0,1;2\n"), Dialect::Semicolon);
        assert_eq!(Dialect::sniff("\n t\tb\n"), Dialect::Tab);
        assert_eq!(Dialect::sniff("t  b\n"), Dialect::Space);
        assert_eq!(Dialect::sniff("\"t\",\"b\",\n"), Dialect::Comma);
        assert_eq!(to_csv("t;b\r\n0,5;1,25\r\n", Dialect::Semicolon), "t,b\n0.5,1.25\n");
        assert_eq!(to_csv("  0.0  -1.4e-3\n", Dialect::Space), "0.0,-1.4e-3\n");
    }
}

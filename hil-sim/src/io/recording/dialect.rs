//! Text recordings as labs save them: the separator (comma, semicolon, tab or spaces) and
//! the decimal mark (a decimal comma goes with a semicolon, tab or space separator) are
//! found from the first line that has any, and the text is rewritten as plain CSV line
//! for line as it is read (so file line numbers stay right, CRLF or not).

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

/// One line of a text recording in `dialect` (without or with its `\n` or `\r\n`) appended to
/// `out` as a CSV line ending in `\n`; decimal commas become points (any comma inside a field,
/// since commas do not separate in these dialects). A line that is not UTF-8 is passed on as
/// it is, for the CSV reader to refuse with its line number.
pub fn line_to_csv(line: &[u8], dialect: Dialect, out: &mut Vec<u8>) {
    let line = line.strip_suffix(b"\n").unwrap_or(line);
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    let text = match std::str::from_utf8(line) {
        Ok(text) if dialect != Dialect::Comma => text,
        _ => {
            out.extend_from_slice(line);
            out.push(b'\n');
            return;
        }
    };
    match dialect {
        Dialect::Semicolon => fields_to_csv(text.split(';'), out),
        Dialect::Tab => fields_to_csv(text.split('\t'), out),
        Dialect::Comma | Dialect::Space => fields_to_csv(text.split_whitespace(), out),
    }
    out.push(b'\n');
}

/// Fields joined by commas, each trimmed, its decimal commas made points.
fn fields_to_csv<'a>(fields: impl Iterator<Item = &'a str>, out: &mut Vec<u8>) {
    for (i, f) in fields.enumerate() {
        if i > 0 {
            out.push(b',');
        }
        out.extend(f.trim().bytes().map(|c| if c == b',' { b'.' } else { c }));
    }
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
        let csv = |text: &str, d| {
            let mut out = Vec::new();
            text.split_inclusive('\n').for_each(|l| line_to_csv(l.as_bytes(), d, &mut out));
            String::from_utf8(out).unwrap()
        };
        assert_eq!(csv("t;b\r\n0,5;1,25\r\n", Dialect::Semicolon), "t,b\n0.5,1.25\n");
        assert_eq!(csv("  0.0  -1.4e-3\n", Dialect::Space), "0.0,-1.4e-3\n");
        assert_eq!(csv("t,b\r\n\"a\",1", Dialect::Comma), "t,b\n\"a\",1\n");
    }
}

//! The CSV dialect a lab's spreadsheet wrote (the separator, a decimal comma: [`CsvDialect`]), the
//! line a record came from ([`LineCounter`]), and a CSV's header and cells as messages may show
//! them ([`header_for_message`], [`cell_for_message`]). The text itself comes from
//! [`crate::text`].

/// A CSV header for a message, under the content rule (RELIABILITY.md, "Inputs"): its column names
/// as short escaped tokens when at least one of `ours` is among them (a CSV of the expected kind with
/// a column misnamed or missing), else nothing of the file's content — only how many fields its first
/// line has (a file named by mistake, or on purpose: `/etc/shadow`, must not be echoed).
pub fn header_for_message<'a>(header: impl IntoIterator<Item = &'a str>, ours: &[&str]) -> String {
    let names: Vec<&str> = header.into_iter().collect();
    let recognised = names
        .iter()
        .any(|h| ours.iter().any(|o| h.trim().eq_ignore_ascii_case(o)));
    if recognised {
        names
            .iter()
            .map(|n| crate::escape::token(n))
            .collect::<Vec<_>>()
            .join(",")
    } else {
        format!(
            "a first line of {} field(s), none of them a column read here; the file's content is \
             not shown — is this the right file?",
            names.len()
        )
    }
}

/// A cell of a recognised CSV file for a message: `"…"`, a short escaped token
/// ([`crate::escape::token`]).
pub fn cell_for_message(cell: &str) -> String {
    format!("\"{}\"", crate::escape::token(cell))
}

/// How a CSV file separates columns, and whether its numbers may use a decimal comma.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CsvDialect {
    /// The column separator: `,`, `;` or a tab.
    pub delimiter: u8,
    /// True when numbers may be written with a decimal comma (`0,5`): the separator is not a comma.
    pub decimal_comma: bool,
}

impl CsvDialect {
    /// The dialect of a CSV text, read from its first line that is neither blank nor a `#` comment:
    /// the most frequent of `,`, `;` and tab outside double quotes (a comma on a tie, and when there
    /// is none).
    pub fn detect(text: &str) -> Self {
        let header = text
            .lines()
            .map(str::trim)
            .find(|l| !l.is_empty() && !l.starts_with('#'))
            .unwrap_or("");
        let (mut comma, mut semicolon, mut tab, mut quoted) = (0usize, 0usize, 0usize, false);
        for c in header.chars() {
            match c {
                '"' => quoted = !quoted,
                ',' if !quoted => comma += 1,
                ';' if !quoted => semicolon += 1,
                '\t' if !quoted => tab += 1,
                _ => {}
            }
        }
        let delimiter = if semicolon > comma && semicolon >= tab {
            b';'
        } else if tab > comma && tab > semicolon {
            b'\t'
        } else {
            b','
        };
        Self {
            delimiter,
            decimal_comma: delimiter != b',',
        }
    }

    /// A `csv` reader for this dialect: `#` comments, fields trimmed, a header row.
    pub fn reader_builder(&self) -> csv::ReaderBuilder {
        let mut builder = csv::ReaderBuilder::new();
        builder
            .delimiter(self.delimiter)
            .comment(Some(b'#'))
            .trim(csv::Trim::All);
        builder
    }

    /// The separator as text for messages: `,`, `;` or `tab`.
    pub fn delimiter_name(&self) -> &'static str {
        match self.delimiter {
            b';' => "';'",
            b'\t' => "tab",
            _ => "','",
        }
    }

    /// Parses a number as Rust does (`0.5`, `1e-3`, `NaN`, `inf`), or with a decimal comma (`0,5`)
    /// when the dialect allows one. Thousands separators are not numbers. Finiteness is the caller's
    /// to check.
    pub fn parse_f64(&self, cell: &str) -> Option<f64> {
        let cell = cell.trim();
        if self.decimal_comma && cell.contains(',') {
            if cell.contains('.') || cell.matches(',').count() > 1 {
                return None;
            }
            return cell.replacen(',', ".", 1).parse().ok();
        }
        cell.parse().ok()
    }

    /// A hint for a row that has more fields than the header (`found` > `expected`): in a
    /// comma-separated file that is usually a decimal comma.
    pub fn extra_fields_hint(&self, expected: usize, found: usize) -> String {
        let mut hint = format!(
            "this row has {found} fields but the header has {expected} (columns separated by {})",
            self.delimiter_name()
        );
        if self.delimiter == b',' {
            hint.push_str(
                "; if the numbers use decimal commas (0,5), separate the columns with ';' (a \
                 spreadsheet's \"CSV (semicolon-separated)\" export) or write decimal points",
            );
        }
        hint
    }
}

/// The 1-based line numbers of CSV records, from their byte offsets. The `csv` crate's own line
/// counter skips blank and comment lines, and a record's offset can point at blank or `#` lines
/// before it, so those are stepped over here. Records are looked up in file order, so counting is
/// incremental: linear in the file size overall (a lookup before the previous one recounts).
#[derive(Debug, Clone)]
pub struct LineCounter<'a> {
    bytes: &'a [u8],
    byte: usize,
    line: u64,
}

impl<'a> LineCounter<'a> {
    /// A counter over `text`.
    pub fn new(text: &'a str) -> Self {
        Self {
            bytes: text.as_bytes(),
            byte: 0,
            line: 1,
        }
    }

    /// The line of the record at `position` (0 when there is none).
    pub fn line(&mut self, position: Option<&csv::Position>) -> u64 {
        let Some(p) = position else { return 0 };
        let bytes = self.bytes;
        let mut start = usize::try_from(p.byte())
            .unwrap_or(usize::MAX)
            .min(bytes.len());
        while start < bytes.len() {
            let rest = &bytes[start..];
            let end = rest
                .iter()
                .position(|&b| b == b'\n')
                .map_or(rest.len(), |i| i + 1);
            let line = rest[..end].trim_ascii();
            if !(line.is_empty() || line.starts_with(b"#")) || end == rest.len() {
                break;
            }
            start += end;
        }
        if start < self.byte {
            self.byte = 0;
            self.line = 1;
        }
        self.line += bytes[self.byte..start]
            .iter()
            .filter(|&&b| b == b'\n')
            .count() as u64;
        self.byte = start;
        self.line
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dialect_detection_and_decimal_commas() {
        let d = CsvDialect::detect("# a;b;c\n\nwavelength_nm;sci;sce\n400;0,5;0,4\n");
        assert_eq!((d.delimiter, d.decimal_comma), (b';', true));
        assert_eq!(d.parse_f64("0,0712"), Some(0.0712));
        assert_eq!(d.parse_f64("1,5e-3"), Some(1.5e-3));
        assert_eq!(d.parse_f64("1.234,5"), None, "thousands separator");
        assert_eq!(d.parse_f64("0.5"), Some(0.5), "a decimal point still reads");
        let d = CsvDialect::detect("file\ttime_s\na.png\t0,01\n");
        assert_eq!((d.delimiter, d.decimal_comma), (b'\t', true));
        let d = CsvDialect::detect("\"a;b\",c\n");
        assert_eq!((d.delimiter, d.decimal_comma), (b',', false));
        assert_eq!(
            d.parse_f64("0,5"),
            None,
            "no decimal comma in a comma-separated file"
        );
        assert_eq!(CsvDialect::detect("").delimiter, b',');
    }
}

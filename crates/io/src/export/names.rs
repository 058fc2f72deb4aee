//! Names and text in the exported files: unique, stable identifiers (slug + hash), Blender's name
//! length, and escaping for each format's comments and literals; number formatting.

/// A number as renderers' parsers read it: 7 significant digits (beyond any measurement's precision
/// and f32's), shortest form, plain decimal between 1e-4 and 1e7 and exponent notation outside.
/// Every number reaching it is finite ([`RendererParameters::from_result`](super::RendererParameters::from_result) checks them); a
/// non-finite one would be written `0` rather than a token no parser reads.
pub fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return "0".into();
    }
    let rounded: f64 = format!("{x:.6e}").parse().unwrap_or(x);
    let a = rounded.abs();
    if (1e-4..1e7).contains(&a) {
        format!("{rounded}")
    } else {
        format!("{rounded:e}")
    }
}

/// The names a material gets in the exports, all derived from the result's name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MaterialNames {
    /// An identifier valid as an XML `id`, a pbrt name and a Python identifier: ASCII letters, digits
    /// and `_`, starting with a letter, at most 52 characters: a slug of the name (≤ 40 characters,
    /// `material` when nothing is left) and `_` and [`name_hash`]. Never empty; stable; different
    /// names give different identifiers (up to a 32-bit hash collision, ≈ 10⁻⁹ for any two names).
    pub id: String,
    /// The material's name in Blender: the name itself when it is a clean Blender name (1–63 bytes
    /// of UTF-8, no control or non-characters, and not itself ending like a hashed name), otherwise
    /// its first bytes (whole characters, cleaned) and ` #` and the hash, within 63 bytes. So two
    /// different names never share a Blender material, and the same name finds its material again
    /// (Blender truncates longer names, which made a new material on every run).
    pub blender: String,
    /// The name for comments: one line, every character safe in every format's comment.
    pub display: String,
}

/// Blender's limit on ID names in bytes (`MAX_ID_NAME` − 3 = 63 in Blender 4.x and 5.0).
pub const BLENDER_NAME_BYTES: usize = 63;

impl MaterialNames {
    /// The names of a material called `name`.
    pub fn new(name: &str) -> Self {
        let hash = name_hash(name);
        let mut slug = String::new();
        for ch in name.chars() {
            let c = if ch.is_ascii_alphanumeric() { ch } else { '_' };
            if !(c == '_' && (slug.is_empty() || slug.ends_with('_'))) {
                slug.push(c);
            }
            if slug.len() >= 40 {
                break;
            }
        }
        let slug = slug.trim_end_matches('_');
        let id = if slug.is_empty() {
            format!("material_{hash}")
        } else if slug.starts_with(|c: char| c.is_ascii_digit()) {
            format!("m_{slug}_{hash}")
        } else {
            format!("{slug}_{hash}")
        };
        let clean = !name.is_empty()
            && name.len() <= BLENDER_NAME_BYTES
            && name.chars().all(|c| !unsafe_char(c))
            && !looks_hashed(name);
        let blender = if clean {
            name.to_string()
        } else {
            let suffix = format!(" #{hash}");
            let mut head = String::new();
            for ch in one_line(name).chars() {
                if head.len() + ch.len_utf8() + suffix.len() > BLENDER_NAME_BYTES {
                    break;
                }
                head.push(ch);
            }
            format!("{head}{suffix}")
        };
        let display = if name.is_empty() {
            "(unnamed)".to_string()
        } else {
            one_line(name)
        };
        Self {
            id,
            blender,
            display,
        }
    }
}

/// True for a name ending like the Blender names [`MaterialNames`] makes for unclean names (` #` and
/// eight lower-case hex digits).
pub(super) fn looks_hashed(name: &str) -> bool {
    let b = name.as_bytes();
    b.len() >= 10
        && &b[b.len() - 10..b.len() - 8] == b" #"
        && b[b.len() - 8..]
            .iter()
            .all(|c| c.is_ascii_digit() || (b'a'..=b'f').contains(c))
}

/// Eight lower-case hex digits of a 64-bit FNV-1a hash of the name's UTF-8 bytes, mixed by the
/// SplitMix64 finaliser (Steele, Lea & Flood 2014) so that every bit depends on every byte. Stable
/// across versions and platforms (no `std` hasher, whose output may change).
pub fn name_hash(name: &str) -> String {
    // FNV-1a, 64 bits (Fowler, Noll & Vo; offset basis and prime from the reference).
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in name.as_bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    // SplitMix64's finaliser.
    h = (h ^ (h >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h = (h ^ (h >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    h ^= h >> 31;
    format!("{:08x}", h >> 32)
}

/// The identifier of a material called `name` ([`MaterialNames::id`]).
pub fn identifier(name: &str) -> String {
    MaterialNames::new(name).id
}

/// A character no export writes as it is inside free text: control characters (C0, DEL, C1), line
/// and paragraph separators, Unicode non-characters (U+FDD0–U+FDEF and the last two code points of
/// every plane: U+FFFE/U+FFFF make XML ill-formed) and the bidirectional controls that can make a
/// line display differently from what it is.
pub(super) fn unsafe_char(c: char) -> bool {
    let u = c as u32;
    c.is_control()
        || matches!(u, 0x2028 | 0x2029 | 0xFDD0..=0xFDEF)
        || (u & 0xFFFE) == 0xFFFE
        || matches!(u, 0x202A..=0x202E | 0x2066..=0x2069 | 0x200E | 0x200F | 0x061C)
}

/// Free text as one line safe in every format's comments and strings of this module: whitespace
/// controls (tab, newline, carriage return, form feed, NEL, line and paragraph separators) become a
/// space, every other `unsafe_char` U+FFFD (�).
pub fn one_line(text: &str) -> String {
    text.chars()
        .map(|c| match c {
            '\t' | '\n' | '\r' | '\u{b}' | '\u{c}' | '\u{85}' | '\u{2028}' | '\u{2029}' => ' ',
            c if unsafe_char(c) => '\u{fffd}',
            c => c,
        })
        .collect()
}

/// `text` with every line longer than `width` characters broken at spaces, continuation lines
/// indented like the line they continue (a word longer than the width stays whole).
pub(super) fn wrap(text: &str, width: usize) -> String {
    let mut out = Vec::new();
    for line in text.split('\n') {
        let indent: String = line.chars().take_while(|c| *c == ' ').collect();
        let mut current = String::new();
        for word in line.trim_start_matches(' ').split(' ') {
            let len = current.chars().count();
            if len > indent.len() && len + 1 + word.chars().count() > width {
                out.push(std::mem::take(&mut current));
            }
            if current.is_empty() {
                current.push_str(&indent);
            } else {
                current.push(' ');
            }
            current.push_str(word);
        }
        out.push(current);
    }
    out.join("\n")
}

/// Text safe inside an XML comment (`<!-- … -->`): [`one_line`] line by line (our own newlines kept),
/// no `--` (forbidden in comments) and no `-` at the end (it would make `--->`).
pub fn xml_comment(text: &str) -> String {
    let lines: Vec<String> = text.split('\n').map(one_line).collect();
    let mut s = lines.join("\n");
    while s.contains("--") {
        s = s.replace("--", "- -");
    }
    if s.ends_with('-') {
        s.push(' ');
    }
    s
}

/// A Python string literal for `text`, in pure ASCII: `\\`, `\"`, `\n`, `\r`, `\t`, `\xNN` for the
/// other control characters, `\uXXXX`/`\UXXXXXXXX` for every non-ASCII character. Python reads it back
/// as exactly `text` (Python Language Reference, §2.4.1 "String and Bytes literals").
pub fn python_literal(text: &str) -> String {
    let mut s = String::with_capacity(text.len() + 2);
    s.push('"');
    for c in text.chars() {
        match c {
            '\\' => s.push_str("\\\\"),
            '"' => s.push_str("\\\""),
            '\n' => s.push_str("\\n"),
            '\r' => s.push_str("\\r"),
            '\t' => s.push_str("\\t"),
            c if (c as u32) < 0x20 || c as u32 == 0x7f => {
                s.push_str(&format!("\\x{:02x}", c as u32));
            }
            c if c.is_ascii() => s.push(c),
            c if (c as u32) <= 0xFFFF => s.push_str(&format!("\\u{:04x}", c as u32)),
            c => s.push_str(&format!("\\U{:08x}", c as u32)),
        }
    }
    s.push('"');
    s
}

/// Text safe inside a Python triple-quoted docstring: [`one_line`], no backslashes (they would start
/// escapes) and no double quotes (no `"""`, and no `"` before the closing quotes).
pub fn python_docstring_text(text: &str) -> String {
    one_line(text)
        .chars()
        .map(|c| match c {
            '\\' => '/',
            '"' => '\'',
            c => c,
        })
        .collect()
}

//! Property-based fuzzing of every text format we read (RELIABILITY.md): the spectro CSV, the
//! exposures CSV, the response CSV, the profile CSV and `result.json`, each fed arbitrary bytes and
//! structured mutations of a valid file (truncation, swapped columns, BOM, CRLF, `;` separators with
//! decimal commas, UTF-16, Latin-1 comments, huge numbers, NaN/inf, inserted bytes, dropped and
//! repeated lines). Every case must give `Ok` or a typed error, never a panic, and within a time
//! bound (a hang or a quadratic blow-up fails the case). Mutations that a lab's files commonly carry
//! (BOM, CRLF, `;` + decimal comma, UTF-16 with BOM, Latin-1 comments) must parse to exactly what
//! the original file parses to.
//!
//! CI runs [`CI_CASES`] cases per property (seconds); `PROPTEST_CASES=20000 cargo test --release -p
//! scatterfit-io --test suite fuzz_text::` runs a long campaign (RELIABILITY.md).

use std::path::Path;
use std::time::{Duration, Instant};

use proptest::prelude::*;
use scatterfit_io::bracket::parse_exposures_bytes;
use scatterfit_io::profile_csv::parse_profile_bytes;
use scatterfit_io::response_csv::parse_response_bytes;
use scatterfit_io::result_json::parse_result_json_bytes;
use scatterfit_io::spectro::parse_spectro_bytes;

/// Cases per property when `PROPTEST_CASES` is not set: small, so the suite stays fast.
const CI_CASES: u32 = 48;

/// A parse of a file of at most a few hundred kilobytes must end well within this.
const TIME_BOUND: Duration = Duration::from_secs(5);

fn config() -> ProptestConfig {
    let mut config = ProptestConfig::default();
    if std::env::var_os("PROPTEST_CASES").is_none() {
        config.cases = CI_CASES;
    }
    config.failure_persistence = None;
    config
}

/// A parser under test: bytes → the parse's `Debug` text (so NaN compares equal to NaN) or the
/// error's message.
type Parser = fn(&[u8]) -> Result<String, String>;

fn spectro(b: &[u8]) -> Result<String, String> {
    parse_spectro_bytes(b, Path::new("s/spectro.csv"))
        .map(|r| format!("{r:?}"))
        .map_err(|e| e.to_string())
}
fn exposures(b: &[u8]) -> Result<String, String> {
    parse_exposures_bytes(b, Path::new("s/exposures.csv"))
        .map(|r| format!("{r:?}"))
        .map_err(|e| e.to_string())
}
fn response(b: &[u8]) -> Result<String, String> {
    parse_response_bytes(b, Path::new("s/response.csv"))
        .map(|r| format!("{r:?}"))
        .map_err(|e| e.to_string())
}
fn profile(b: &[u8]) -> Result<String, String> {
    parse_profile_bytes(b, Path::new("s/profile.csv"))
        .map(|r| format!("{r:?}"))
        .map_err(|e| e.to_string())
}
fn result_json(b: &[u8]) -> Result<String, String> {
    parse_result_json_bytes(b, Path::new("s/result.json"))
        .map(|r| format!("{r:?}"))
        .map_err(|e| e.to_string())
}

fn valid_spectro() -> String {
    let mut s = String::from("# CM-600d export\nwavelength_nm,sci,sce\n");
    for i in 0..31 {
        let w = 400 + 10 * i;
        s.push_str(&format!(
            "{w},{:.4},{:.4}\n",
            0.55 + 0.001 * i as f64,
            0.51 + 0.001 * i as f64
        ));
    }
    s
}
fn valid_exposures() -> String {
    "file,time_s\n# shortest first\nimg_01.png,1/600\nimg_02.png,0.0125\nimg_03.png,0.1\n\
     img_04.png,1.5e-1\n"
        .into()
}
fn valid_response() -> String {
    let mut s = String::from("z,g_r,g_g,g_b\n");
    for z in 0..256 {
        let g = 2.2 * ((z as f64 + 0.5) / 128.5).ln();
        s.push_str(&format!("{z},{g},{},{}\n", g + 0.01, g - 0.01));
    }
    s
}
fn valid_profile() -> String {
    let mut s = String::from(
        "r_mm,r_px,value_r,stderr_r,count_r,value_g,stderr_g,count_g,value_b,stderr_b,count_b\n",
    );
    for k in 0..40 {
        let v = 1500.0 * (-0.1 * k as f64).exp();
        s.push_str(&format!(
            "{},{},{v},{},{},{},{},{},,,0\n",
            0.05 + 0.1 * k as f64,
            0.5 + k as f64,
            v * 0.01,
            8 * (k + 1),
            v * 0.9,
            v * 0.009,
            8 * (k + 1)
        ));
    }
    s
}
fn valid_result() -> String {
    let channel = |sp: f64, sa: f64| {
        format!(
            r#"{{ "status": "ok", "sigma_s_prime": {sp}, "sigma_s_prime_stderr": 0.004, "sigma_a": {sa},
               "sigma_a_stderr": 2e-5, "albedo_prime": {}, "rd_total": 0.87, "fit_time_s": 1.2e-5,
               "iterations": 9, "mse": 0.8 }}"#,
            sp / (sp + sa)
        )
    };
    format!(
        r#"{{ "name": "pink plastic", "eta": 1.2886, "method": "proposed", "model": "dipole",
  "channels": {{ "r": {}, "g": {}, "b": {} }},
  "inputs": {{ "sample_dir": "s", "options": {{ "r_max_px": 300 }} }}, "version": "0.1.0" }}
"#,
        channel(1.979, 0.000792),
        channel(1.893, 0.0496),
        channel(1.992, 0.0227)
    )
}

/// A change to a valid file.
#[derive(Debug, Clone)]
enum Mutation {
    /// Cut the bytes at this fraction of the length.
    Truncate(f64),
    /// Swap two columns on every line that has both.
    SwapColumns(usize, usize),
    /// Replace the k-th number with this text.
    ReplaceNumber(usize, &'static str),
    /// Insert raw bytes at this fraction of the length.
    InsertBytes(f64, Vec<u8>),
    /// Drop line k.
    DropLine(usize),
    /// Repeat line k n times.
    RepeatLine(usize, usize),
    /// Replace byte at this fraction with this value.
    SetByte(f64, u8),
}

/// A re-encoding that a lab's file commonly has and that must parse to the same values.
#[derive(Debug, Clone, Copy)]
enum Harmless {
    Bom,
    Crlf,
    SemicolonDecimalComma,
    Utf16Le,
    Utf16Be,
    Latin1Comment,
}

const NASTY_NUMBERS: &[&str] = &[
    "1e308",
    "-1e308",
    "1e400",
    "-1e400",
    "1e-400",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "infinity",
    "",
    "-0",
    "0x10",
    "１",
    "99999999999999999999999999999999",
    "18446744073709551616",
    "-1",
    "1/0",
    "0/0",
    "1,5",
    "1.234,5",
    "\"",
    "\"0.5\"",
    "#",
];

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (0.0..1.0f64).prop_map(Mutation::Truncate),
        (0..12usize, 0..12usize).prop_map(|(a, b)| Mutation::SwapColumns(a, b)),
        (0..300usize, proptest::sample::select(NASTY_NUMBERS))
            .prop_map(|(k, t)| Mutation::ReplaceNumber(k, t)),
        (0.0..1.0f64, proptest::collection::vec(any::<u8>(), 1..8))
            .prop_map(|(f, b)| Mutation::InsertBytes(f, b)),
        (0..300usize).prop_map(Mutation::DropLine),
        (0..300usize, 2..50usize).prop_map(|(k, n)| Mutation::RepeatLine(k, n)),
        (0.0..1.0f64, any::<u8>()).prop_map(|(f, b)| Mutation::SetByte(f, b)),
    ]
}

fn harmless() -> impl Strategy<Value = Harmless> {
    prop_oneof![
        Just(Harmless::Bom),
        Just(Harmless::Crlf),
        Just(Harmless::SemicolonDecimalComma),
        Just(Harmless::Utf16Le),
        Just(Harmless::Utf16Be),
        Just(Harmless::Latin1Comment),
    ]
}

fn is_number(field: &str) -> bool {
    let f = field.trim();
    f.parse::<f64>().is_ok()
        || f.split_once('/').is_some_and(|(a, b)| {
            a.trim().parse::<f64>().is_ok() && b.trim().parse::<f64>().is_ok()
        })
}

/// Applies a text-level mutation.
fn mutate_text(text: &str, m: &Mutation) -> Vec<u8> {
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    match m {
        Mutation::SwapColumns(a, b) => {
            for line in &mut lines {
                let mut f: Vec<&str> = line.split(',').collect();
                if *a < f.len() && *b < f.len() {
                    f.swap(*a, *b);
                }
                *line = f.join(",");
            }
        }
        Mutation::ReplaceNumber(k, t) => {
            let mut seen = 0;
            'outer: for line in &mut lines {
                let mut f: Vec<String> = line.split(',').map(str::to_owned).collect();
                for field in &mut f {
                    if is_number(field) {
                        if seen == *k {
                            *field = (*t).to_owned();
                            *line = f.join(",");
                            break 'outer;
                        }
                        seen += 1;
                    }
                }
            }
        }
        Mutation::DropLine(k) if *k < lines.len() => {
            lines.remove(*k);
        }
        Mutation::RepeatLine(k, n) if *k < lines.len() => {
            let l = lines[*k].clone();
            for _ in 0..*n {
                lines.insert(*k, l.clone());
            }
        }
        _ => {}
    }
    let mut bytes = (lines.join("\n") + "\n").into_bytes();
    let at = |f: f64, len: usize| ((f * len as f64) as usize).min(len);
    match m {
        Mutation::Truncate(f) => bytes.truncate(at(*f, bytes.len())),
        Mutation::InsertBytes(f, b) => {
            let i = at(*f, bytes.len());
            bytes.splice(i..i, b.iter().copied());
        }
        Mutation::SetByte(f, b) if !bytes.is_empty() => {
            let i = at(*f, bytes.len() - 1);
            bytes[i] = *b;
        }
        _ => {}
    }
    bytes
}

/// Re-encodes a CSV text as a lab's software might have written it.
fn harmless_csv(text: &str, h: Harmless) -> Vec<u8> {
    match h {
        Harmless::Bom => [&[0xEF, 0xBB, 0xBF][..], text.as_bytes()].concat(),
        Harmless::Crlf => text.replace('\n', "\r\n").into_bytes(),
        Harmless::SemicolonDecimalComma => text
            .lines()
            .map(|l| {
                if l.trim_start().starts_with('#') {
                    l.to_owned()
                } else {
                    l.split(',')
                        .map(|f| {
                            if is_number(f) {
                                f.replace('.', ",")
                            } else {
                                f.to_owned()
                            }
                        })
                        .collect::<Vec<_>>()
                        .join(";")
                }
            })
            .map(|l| l + "\n")
            .collect::<String>()
            .into_bytes(),
        Harmless::Utf16Le | Harmless::Utf16Be => utf16(text, matches!(h, Harmless::Utf16Le)),
        Harmless::Latin1Comment => {
            // The file, then "# Probe grün, 23 °C, µm" in Latin-1 (at the end, so line numbers stay).
            let mut b = text.as_bytes().to_vec();
            b.extend_from_slice(b"# Probe gr\xFCn, 23 \xB0C, \xB5m\n");
            b
        }
    }
}

fn utf16(text: &str, little: bool) -> Vec<u8> {
    let mut out = if little {
        vec![0xFF, 0xFE]
    } else {
        vec![0xFE, 0xFF]
    };
    for u in text.encode_utf16() {
        out.extend(if little {
            u.to_le_bytes()
        } else {
            u.to_be_bytes()
        });
    }
    out
}

/// Runs a parser, failing the case if it takes too long (a panic fails it by itself).
fn timed(parser: Parser, bytes: &[u8]) -> Result<String, String> {
    let start = Instant::now();
    let r = parser(bytes);
    let elapsed = start.elapsed();
    assert!(
        elapsed < TIME_BOUND,
        "parse of {} bytes took {elapsed:?}",
        bytes.len()
    );
    r
}

/// A format's name, parser and valid file.
type Format = (&'static str, Parser, fn() -> String);

const CSV_PARSERS: [Format; 4] = [
    ("spectro", spectro, valid_spectro),
    ("exposures", exposures, valid_exposures),
    ("response", response, valid_response),
    ("profile", profile, valid_profile),
];

#[test]
fn valid_files_parse() {
    for (name, parser, valid) in CSV_PARSERS {
        assert!(parser(valid().as_bytes()).is_ok(), "{name}");
    }
    assert!(result_json(valid_result().as_bytes()).is_ok());
}

proptest! {
    #![proptest_config(config())]

    /// Arbitrary bytes: Ok or a typed error, never a panic or a hang.
    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2048)) {
        for (_, parser, _) in CSV_PARSERS {
            let _ = timed(parser, &bytes);
        }
        let _ = timed(result_json, &bytes);
    }

    /// CSV-looking noise (digits, separators, quotes, newlines, a header): reaches deeper than
    /// uniform bytes.
    #[test]
    fn csv_like_noise_never_panics(
        body in proptest::collection::vec(
            proptest::sample::select(&[
                "0", "1", "9", ".", ",", ";", "\t", "\n", "\r\n", "\"", "#", "-", "e", "/",
                "NaN", "inf", " ", "\u{feff}", "é", "\0",
            ][..]),
            0..400,
        ),
        header in proptest::sample::select(&[
            "wavelength_nm,sci,sce\n", "wavelength_nm;sci_pct;sce_pct\n", "file,time_s\n",
            "z,g_r,g_g,g_b\n", "z,g\n", "r_mm,r_px,value_y,stderr_y,count_y\n", "",
        ][..]),
    ) {
        let text = format!("{header}{}", body.concat());
        for (_, parser, _) in CSV_PARSERS {
            let _ = timed(parser, text.as_bytes());
        }
    }

    /// Structured mutations of valid files: Ok or a typed error, never a panic or a hang.
    #[test]
    fn mutated_files_never_panic(
        which in 0..5usize,
        mutations in proptest::collection::vec(mutation(), 1..4),
        wrap in proptest::option::of(harmless()),
    ) {
        let (parser, valid): (Parser, fn() -> String) = if which < 4 {
            (CSV_PARSERS[which].1, CSV_PARSERS[which].2)
        } else {
            (result_json, valid_result)
        };
        let mut bytes = valid().into_bytes();
        for m in &mutations {
            let text = String::from_utf8_lossy(&bytes).into_owned();
            bytes = mutate_text(&text, m);
        }
        if let Some(h) = wrap {
            let text = String::from_utf8_lossy(&bytes).into_owned();
            bytes = harmless_csv(&text, h);
        }
        let _ = timed(parser, &bytes);
    }

    /// A lab's common encodings and separators parse to exactly what the plain file parses to.
    #[test]
    fn harmless_reencodings_parse_identically(which in 0..4usize, h in harmless()) {
        let (name, parser, valid) = CSV_PARSERS[which];
        let text = valid();
        let plain = parser(text.as_bytes());
        prop_assert!(plain.is_ok(), "{}", name);
        let wrapped = timed(parser, &harmless_csv(&text, h));
        prop_assert_eq!(wrapped, plain, "{} {:?}", name, h);
    }
}

/// The same for `result.json`: BOM, CRLF and UTF-16 with BOM are accepted.
#[test]
fn result_json_encodings_parse_identically() {
    let text = valid_result();
    let plain = result_json(text.as_bytes()).unwrap();
    for h in [
        Harmless::Bom,
        Harmless::Crlf,
        Harmless::Utf16Le,
        Harmless::Utf16Be,
    ] {
        assert_eq!(
            result_json(&harmless_csv(&text, h)).unwrap(),
            plain,
            "{h:?}"
        );
    }
}

/// Deeply nested JSON is refused by serde_json's recursion limit, not a stack overflow.
#[test]
fn deeply_nested_json_is_refused() {
    let deep = "[".repeat(100_000);
    assert!(result_json(deep.as_bytes()).is_err());
    let deep = format!("{{\"inputs\": {{\"options\": {}", "{\"a\":".repeat(50_000));
    assert!(result_json(deep.as_bytes()).is_err());
}

/// An enormous file is refused from its size, before it is read; a large one (hundreds of
/// thousands of rows) parses in linear time.
#[test]
fn enormous_files_are_refused_and_large_ones_parse_fast() {
    use scatterfit_io::text::MAX_TEXT_FILE_BYTES;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.csv");
    let f = std::fs::File::create(&path).unwrap();
    f.set_len(MAX_TEXT_FILE_BYTES + 1).unwrap(); // sparse: no disk or memory used
    drop(f);
    let start = Instant::now();
    let e = scatterfit_io::spectro::read_spectro_csv(&path)
        .unwrap_err()
        .to_string();
    assert!(e.contains("more than") && e.contains("huge.csv"), "{e}");
    let e = scatterfit_io::response_csv::read_response_csv(&path)
        .unwrap_err()
        .to_string();
    assert!(e.contains("more than"), "{e}");
    assert!(start.elapsed() < Duration::from_secs(1));

    // 400 000 rows (≈ 9 MB): refused at the row cap (a spectrum has one row per wavelength),
    // quickly — the reader stops there instead of numbering every line.
    let mut big = String::from("wavelength_nm,sci,sce\n");
    for i in 0..400_000 {
        big.push_str(&format!("{},0.5,0.4\n", 400.0 + i as f64 * 0.00075));
    }
    big.push_str("700,0.5,zzz\n");
    let start = Instant::now();
    let e = spectro(big.as_bytes()).unwrap_err();
    assert!(e.contains("more than 10000 rows"), "{e}");
    assert!(start.elapsed() < TIME_BOUND, "{:?}", start.elapsed());
}

/// The refused forms name what they saw and how to re-save the file.
#[test]
fn refused_forms_say_how_to_resave() {
    let text = valid_spectro();
    // UTF-16 without a BOM.
    let no_bom = utf16(&text, true)[2..].to_vec();
    let e = spectro(&no_bom).unwrap_err();
    assert!(
        e.contains("UTF-16 without a byte-order mark") && e.contains("CSV UTF-8"),
        "{e}"
    );
    // A workbook.
    let e = exposures(b"PK\x03\x04\x14\x00\x00\x00\x08\x00").unwrap_err();
    assert!(e.contains(".xlsx") && e.contains("CSV UTF-8"), "{e}");
    // Decimal commas in a comma-separated file: more fields than the header.
    let e = spectro(text.replace("0.55", "0,55").as_bytes()).unwrap_err();
    assert!(e.contains("decimal comma") && e.contains("';'"), "{e}");
    let e = exposures(b"file,time_s\na.png,0,01\n").unwrap_err();
    assert!(e.contains("line 2") && e.contains("decimal comma"), "{e}");
    let e = response(valid_response().replace("0,-", "0,-5,1,").as_bytes()).unwrap_err();
    assert!(e.contains("decimal comma"), "{e}");
    // Thousands separators are not numbers.
    let e = spectro(
        harmless_csv(&text, Harmless::SemicolonDecimalComma)
            .iter()
            .map(|&b| b as char)
            .collect::<String>()
            .replacen("400;", "1.400,0;", 1)
            .as_bytes(),
    )
    .unwrap_err();
    assert!(e.contains("not a number"), "{e}");
}

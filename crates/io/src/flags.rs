//! Numbers as people write them on a command line: counts (`1e6`, `1_000_000`), finite decimals,
//! and short comma-separated lists (`R,G,B`, `X,Y`, `LO,HI`). These are the value parsers of the
//! `scatterfit` binary's flags, kept here so that the settings structs of the library crates that
//! derive `clap::Args` (behind their `clap` feature) parse their flags exactly as the binary does.
//! Every refusal says what was given and how to write it.

/// A value that is not what its flag takes; the message names the text and how to write it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct FlagError(pub String);

fn refuse<T>(message: String) -> Result<T, FlagError> {
    Err(FlagError(message))
}

/// Parses a count: `1000000`, `1e6`, `2.5e5` or `1_000_000`; a whole number ≥ 0 that fits in u64
/// (decimal notation must be exact: at most 2⁵³ when written with an exponent or a point).
///
/// # Errors
/// A message naming what was wrong.
pub fn parse_count(text: &str) -> Result<u64, FlagError> {
    let t = text.trim().replace('_', "");
    if let Ok(n) = t.parse::<u64>() {
        return Ok(n);
    }
    let Ok(v) = t.parse::<f64>() else {
        return refuse(format!(
            "`{text}` is not a count (write e.g. 1000000 or 1e6)"
        ));
    };
    if !v.is_finite() || v < 0.0 {
        return refuse(format!("`{text}` is not a count ≥ 0"));
    }
    if v.fract() != 0.0 {
        return refuse(format!("`{text}` is not a whole number"));
    }
    const EXACT: f64 = 9_007_199_254_740_992.0; // 2⁵³
    if v > EXACT {
        return refuse(format!(
            "`{text}` is too large for a count in floating-point notation (at most 2⁵³ ≈ 9.0e15); \
             write the digits"
        ));
    }
    Ok(v as u64)
}

/// A memory budget in MiB (`--max-memory-mib`): a count ≥ 1.
///
/// # Errors
/// As [`parse_count`], or 0.
pub fn parse_mib(text: &str) -> Result<u64, FlagError> {
    match parse_count(text)? {
        0 => refuse("a memory budget of 0 MiB allows nothing; give at least 1".into()),
        n => Ok(n),
    }
}

/// [`parse_count`] for sizes held in `usize`.
///
/// # Errors
/// As [`parse_count`], or a count that does not fit this machine's `usize`.
pub fn parse_size(text: &str) -> Result<usize, FlagError> {
    let n = parse_count(text)?;
    usize::try_from(n).map_err(|_| FlagError(format!("`{text}` is too large")))
}

/// Parses a decimal number, refusing NaN and infinities up front.
///
/// # Errors
/// Not a number, or not a finite one.
pub fn parse_finite(text: &str) -> Result<f64, FlagError> {
    let Ok(v) = text.trim().parse::<f64>() else {
        return refuse(format!("`{text}` is not a number"));
    };
    if v.is_finite() {
        Ok(v)
    } else {
        refuse(format!("`{text}` is not a finite number"))
    }
}

/// A comma-separated list of numbers: how many items there are, and the values of those that are
/// numbers (each item trimmed). The list parsers below decide what a good list is.
fn numbers(text: &str) -> (usize, Vec<f64>) {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let values = parts.iter().filter_map(|p| p.parse::<f64>().ok()).collect();
    (parts.len(), values)
}

/// Parses `R,G,B`: three finite numbers, one per channel.
///
/// # Errors
/// One number (the message shows it written for every channel), or anything but three numbers.
pub fn parse_rgb(text: &str) -> Result<[f64; 3], FlagError> {
    match numbers(text) {
        (3, v) if v.len() == 3 && v.iter().all(|x| x.is_finite()) => Ok([v[0], v[1], v[2]]),
        // One number: say how to give it for every channel (the example is the user's own value).
        (1, v) if v.len() == 1 => {
            let v = v[0];
            refuse(format!(
                "`{text}` is one number; give one per channel, R,G,B (e.g. {v},{v},{v})"
            ))
        }
        _ => refuse(format!(
            "`{text}` is not three numbers R,G,B (one per channel, comma-separated)"
        )),
    }
}

/// Parses `LO,HI` of a range of the Henyey–Greenstein g (`--g-range`): two finite numbers (the
/// range's rule is checked with the other settings).
///
/// # Errors
/// Anything but two finite numbers.
pub fn parse_g_range(text: &str) -> Result<[f64; 2], FlagError> {
    match numbers(text) {
        (2, v) if v.len() == 2 && v.iter().all(|x| x.is_finite()) => Ok([v[0], v[1]]),
        _ => refuse(format!(
            "`{text}` is not a range LO,HI of g (e.g. 0.7,0.95)"
        )),
    }
}

/// Parses a light spot's centre `X,Y` in pixels (`--center`): two finite numbers.
///
/// # Errors
/// Two items that are not both finite numbers, or not two items.
pub fn parse_center(text: &str) -> Result<[f64; 2], FlagError> {
    match numbers(text) {
        (2, v) if v.len() == 2 && v.iter().all(|x| x.is_finite()) => Ok([v[0], v[1]]),
        (2, _) => refuse(format!(
            "`{text}` is not two numbers; write the centre as X,Y in pixels, e.g. 512.3,498.7"
        )),
        _ => refuse(format!(
            "`{text}` is not X,Y; write the centre in pixels, e.g. 512.3,498.7"
        )),
    }
}

/// Parses `--g G|fit` into a manifest's `[fit] g` setting: a number as [`parse_finite`] takes it,
/// else the setting's own text (`fit`).
///
/// # Errors
/// Neither a finite number nor `fit`.
pub fn parse_g(text: &str) -> Result<crate::manifest::GSetting, FlagError> {
    parse_finite(text)
        .map(crate::manifest::GSetting::Value)
        .or_else(|_| text.parse().map_err(FlagError))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_accept_scientific_notation() {
        assert_eq!(parse_count("1e6"), Ok(1_000_000));
        assert_eq!(parse_count("2.5e5"), Ok(250_000));
        assert_eq!(parse_count("1_000_000"), Ok(1_000_000));
        assert_eq!(parse_count("18446744073709551615"), Ok(u64::MAX));
        assert!(parse_count("1.5").unwrap_err().0.contains("whole"));
        assert!(parse_count("-3").is_err());
        assert!(parse_count("1e300").unwrap_err().0.contains("too large"));
        assert!(parse_count("NaN").is_err());
        assert!(parse_count("many").unwrap_err().0.contains("1e6"));
        assert!(parse_mib("0").unwrap_err().0.contains("at least 1"));
    }

    #[test]
    fn lists_take_their_count_of_finite_numbers() {
        assert_eq!(parse_rgb(" 1, 2.5 ,3"), Ok([1.0, 2.5, 3.0]));
        assert!(parse_rgb("0.5").unwrap_err().0.contains("0.5,0.5,0.5"));
        assert!(
            parse_rgb("1,2,inf")
                .unwrap_err()
                .0
                .contains("not three numbers")
        );
        assert!(parse_rgb("1,2").is_err());
        assert_eq!(parse_g_range("0.7,0.95"), Ok([0.7, 0.95]));
        assert!(parse_g_range("0.7").is_err());
        assert_eq!(parse_center("512.3, 498.7"), Ok([512.3, 498.7]));
        assert!(
            parse_center("a,b")
                .unwrap_err()
                .0
                .contains("not two numbers")
        );
        assert!(parse_center("1,2,3").unwrap_err().0.contains("not X,Y"));
        assert!(parse_finite("inf").unwrap_err().0.contains("finite"));
    }
}

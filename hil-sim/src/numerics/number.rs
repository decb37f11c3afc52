//! Numbers as a reader sees them: plain decimals with a few significant digits, and
//! `3.26 × 10⁷` (never `3.26e7`) outside 10⁻³ … 10⁶; always with the unit when it has one.

/// `v` with `sig` significant digits (1–9): plain decimals for 10⁻³ ≤ |v| < 10⁶, a power
/// of ten with superscript digits otherwise; `"0"` for zero, `"—"` for NaN or infinity.
pub fn num(v: f64, sig: usize) -> String {
    let sig = sig.clamp(1, 9);
    if !v.is_finite() {
        return "—".into();
    }
    if v == 0.0 {
        return "0".into();
    }
    let mag = v.abs().log10().floor() as i32;
    if (-3..6).contains(&mag) {
        let decimals = (sig as i32 - 1 - mag).max(0) as usize;
        let s = format!("{v:.decimals$}");
        return if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') { s[1..].to_owned() } else { s };
    }
    let mantissa = v / 10f64.powi(mag);
    // Rounding may carry the mantissa to 10.
    let (m, e) = match format!("{mantissa:.*}", sig - 1) {
        s if s.trim_start_matches('-').starts_with("10") => (mantissa / 10.0, mag + 1),
        _ => (mantissa, mag),
    };
    format!("{m:.*} × 10{}", sig - 1, superscript(e))
}

/// `v` with `sig` significant digits and its unit (`"6.1 ms"`), or the number alone when
/// `unit` is empty.
pub fn with_unit(v: f64, sig: usize, unit: &str) -> String {
    if unit.is_empty() {
        num(v, sig)
    } else {
        format!("{} {unit}", num(v, sig))
    }
}

/// `v` with a sign and `decimals` decimals (`"+1.997"`, `"-0.491"`), and `"+0.000"` rather
/// than `"-0.000"` when `v` rounds to zero; `"—"` for NaN or infinity.
pub fn signed(v: f64, decimals: usize) -> String {
    if !v.is_finite() {
        return "—".into();
    }
    let s = format!("{v:+.decimals$}");
    if s[1..].chars().all(|c| c == '0' || c == '.') {
        format!("+{}", &s[1..])
    } else {
        s
    }
}

fn superscript(e: i32) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::new();
    if e < 0 {
        s.push('⁻');
    }
    for c in e.unsigned_abs().to_string().chars() {
        s.push(c.to_digit(10).and_then(|d| DIGITS.get(d as usize)).copied().unwrap_or(c));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_and_powers_of_ten() {
        assert_eq!(num(0.0061, 2), "0.0061");
        assert_eq!(num(196.53, 4), "196.5");
        assert_eq!(num(-0.68909, 3), "-0.689");
        assert_eq!(num(32_632_510.0, 3), "3.26 × 10⁷");
        assert_eq!(num(3.3619365e-8, 2), "3.4 × 10⁻⁸");
        assert_eq!(num(9.9999e8, 2), "1.0 × 10⁹");
        assert_eq!(num(-0.00001, 2), "-1.0 × 10⁻⁵");
        assert_eq!(num(f64::NAN, 3), "—");
        assert_eq!(num(-0.0004, 1), "-4 × 10⁻⁴");
        assert_eq!(num(-0.0000, 3), "0");
        assert_eq!(with_unit(6.1e-3, 2, "s"), "0.0061 s");
        assert_eq!(with_unit(2.0, 2, ""), "2.0");
        assert!(!num(1e300, 3).contains('e'));
    }

    #[test]
    fn signed_never_shows_minus_zero() {
        assert_eq!(signed(1.9971, 3), "+1.997");
        assert_eq!(signed(-0.4911, 3), "-0.491");
        assert_eq!(signed(-0.0002, 3), "+0.000");
        assert_eq!(signed(-0.0, 2), "+0.00");
        assert_eq!(signed(-0.0006, 3), "-0.001");
        assert_eq!(signed(f64::INFINITY, 3), "—");
    }
}

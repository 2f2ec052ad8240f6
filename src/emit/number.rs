//! The number formats the controller files and the printed advice share.

/// `+0.0023` / `-0.0023` with a fixed number of decimals; never `-0.0000`.
pub fn signed_fixed(value: f64, decimals: usize) -> String {
    let text = format!("{value:+.decimals$}");
    if text.starts_with('-') && text[1..].chars().all(|c| c == '0' || c == '.') {
        return format!("+{}", &text[1..]);
    }
    text
}

/// Minimal digits, up to `max_decimals`, with an explicit sign: `+100`, `+12.5`, `-0.25`.
pub fn signed_minimal(value: f64, max_decimals: usize) -> String {
    let unsigned = minimal(value.abs(), max_decimals);
    let negative = value < 0.0 && unsigned.chars().any(|c| c.is_ascii_digit() && c != '0');
    format!("{}{unsigned}", if negative { '-' } else { '+' })
}

/// Minimal digits, up to `max_decimals`, no sign for positives: `100`, `12.5`, `-0.25`.
pub fn minimal(value: f64, max_decimals: usize) -> String {
    let text = format!("{value:.max_decimals$}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        &text
    };
    if text == "-0" {
        "0".to_string()
    } else {
        text.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn number_formats() {
        assert_eq!(signed_fixed(-0.0023, 4), "-0.0023");
        assert_eq!(signed_fixed(0.0, 4), "+0.0000");
        assert_eq!(signed_fixed(-0.00004, 4), "+0.0000");
        assert_eq!(signed_fixed(0.00005001, 4), "+0.0001");
        assert_eq!(signed_minimal(100.0, 4), "+100");
        assert_eq!(signed_minimal(-12.5, 4), "-12.5");
        assert_eq!(signed_minimal(-0.00001, 4), "+0");
        assert_eq!(minimal(-200.0, 6), "-200");
        assert_eq!(minimal(0.0030000001, 6), "0.003");
        assert_eq!(minimal(-0.0000001, 6), "0");
    }
}

//! What the Fagor 8055 and 8065 leadscrew tables share: a positive-direction
//! and a negative-direction error column per point, holding the axis error
//! actual − target as it is (no sign change), the ranges of the values, and
//! the text encodings the controllers' files come in. Used by `fagor8055` and
//! `fagor8065`; the facts and their sources are in `formats/fagor8055/README.md`
//! and `formats/fagor8065/README.md`.

use crate::compensate::{CompensationTable, TableValues};
use crate::error::ParseError;
use crate::measurement::Direction;

/// \[seen\] Fagor 8055 installation manual §7.5.7 (easymanua.ls page 328):
/// positions and errors take "±99999.9999 mm or ±3937.00787 inches".
pub(crate) const LIMIT_MM: f64 = 99_999.999_9;

/// The two error columns of a table, in mm: the ↑ column and the ↓ column.
/// A mean table writes its values in the positive column and zero in the
/// negative one (\[seen\] 8055 manual: "If the error in the negative direction
/// is zero for all the points, it assumes that the error defined for the
/// positive direction is good for both directions").
pub(crate) fn columns_mm(table: &CompensationTable) -> (Vec<f64>, Vec<f64>) {
    match &table.values {
        TableValues::Mean(values) => (values.clone(), vec![0.0; values.len()]),
        TableValues::Bidirectional { up, down } => (up.clone(), down.clone()),
    }
}

/// The table the read columns stand for: one column when `bidirectional`
/// is false (8055: every negative error zero; 8065: `BIDIR` 0); its
/// reference is its first zero.
pub(crate) fn table_of(
    axis: &str,
    positions_mm: Vec<f64>,
    positive: Vec<f64>,
    negative: Vec<f64>,
    bidirectional: bool,
) -> CompensationTable {
    let values = if bidirectional {
        TableValues::Bidirectional {
            up: positive,
            down: negative,
        }
    } else {
        TableValues::Mean(positive)
    };
    super::table_as_read(axis, positions_mm, values)
}

/// A number with `places` decimals and no sign on a rounded zero, as both
/// controllers' files write them (`0.00000`, never `-0.00000`).
pub(crate) fn fixed(value: f64, places: usize) -> String {
    let text = format!("{value:.places$}");
    match text.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => text,
    }
}

/// Whether a bidirectional table's ↓ column rounds to zero everywhere while
/// its ↑ column does not: a Fagor 8055 would then apply the ↑ column in both
/// directions.
pub(crate) fn down_column_vanishes(table: &CompensationTable, resolution_mm: f64) -> bool {
    let TableValues::Bidirectional { .. } = &table.values else {
        return false;
    };
    let rounds_to_zero = |v: &f64| v.abs() < resolution_mm / 2.0;
    let down = table.values.for_direction(Direction::Down);
    let up = table.values.for_direction(Direction::Up);
    down.iter().all(rounds_to_zero) && !up.iter().all(rounds_to_zero)
}

/// How a table file's bytes were encoded, so an updated file is written back
/// the same way.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextEncoding {
    /// UTF-8 or ASCII, with or without a byte-order mark.
    Utf8 {
        /// Whether the file starts with EF BB BF.
        bom: bool,
    },
    /// UTF-16 little endian with its byte-order mark FF FE (Fagor 8065 exports).
    Utf16Le,
    /// UTF-16 big endian with its byte-order mark FE FF.
    Utf16Be,
}

/// Decodes a table file: UTF-16 with a byte-order mark (LE or BE), else as
/// the measurement readers do (UTF-8, a BOM dropped, or Latin-1).
pub fn decode(bytes: &[u8]) -> Result<(String, TextEncoding), ParseError> {
    let (body, big_endian, encoding) = if let Some(body) = bytes.strip_prefix(&[0xFF, 0xFE]) {
        (body, false, TextEncoding::Utf16Le)
    } else if let Some(body) = bytes.strip_prefix(&[0xFE, 0xFF]) {
        (body, true, TextEncoding::Utf16Be)
    } else {
        let bom = bytes.starts_with(&[0xEF, 0xBB, 0xBF]);
        let text = crate::read::decode(bytes)?.into_owned();
        return Ok((text, TextEncoding::Utf8 { bom }));
    };
    let units = body.chunks(2).map(|pair| match pair {
        [a, b] if big_endian => u16::from_be_bytes([*a, *b]),
        [a, b] => u16::from_le_bytes([*a, *b]),
        // An odd last byte: not a code unit; decode_utf16 sees a lone surrogate.
        _ => 0xD800,
    });
    let mut text = String::with_capacity(body.len() / 2);
    let (mut line, mut column) = (1, 1);
    for unit in char::decode_utf16(units) {
        match unit {
            Ok(c) => {
                text.push(c);
                if c == '\n' {
                    line += 1;
                    column = 1;
                } else {
                    column += 1;
                }
            }
            Err(_) => {
                return Err(ParseError::new(
                    line,
                    column,
                    "expected UTF-16 text, found an invalid code unit (a lone surrogate or an odd last byte)",
                ));
            }
        }
    }
    Ok((text, encoding))
}

/// Encodes text the way [`decode`] found it.
pub fn encode(text: &str, encoding: TextEncoding) -> Vec<u8> {
    match encoding {
        TextEncoding::Utf8 { bom } => {
            let mut bytes = if bom {
                vec![0xEF, 0xBB, 0xBF]
            } else {
                Vec::new()
            };
            bytes.extend_from_slice(text.as_bytes());
            bytes
        }
        TextEncoding::Utf16Le => std::iter::once(0xFEFF)
            .chain(text.encode_utf16())
            .flat_map(u16::to_le_bytes)
            .collect(),
        TextEncoding::Utf16Be => std::iter::once(0xFEFF)
            .chain(text.encode_utf16())
            .flat_map(u16::to_be_bytes)
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utf16_both_byte_orders_round_trip() {
        for encoding in [TextEncoding::Utf16Le, TextEncoding::Utf16Be] {
            let bytes = encode("X AXIS ;3100\r\nµ;1\r\n", encoding);
            let (text, found) = decode(&bytes).unwrap();
            assert_eq!(
                (text.as_str(), found),
                ("X AXIS ;3100\r\nµ;1\r\n", encoding)
            );
        }
        // FF FE, then 'X' 00.
        assert_eq!(&encode("X", TextEncoding::Utf16Le), &[0xFF, 0xFE, b'X', 0]);
        assert_eq!(&encode("X", TextEncoding::Utf16Be), &[0xFE, 0xFF, 0, b'X']);
    }

    #[test]
    fn broken_utf16_is_refused_with_its_position() {
        // "A\nB" then a lone high surrogate D800 (LE: 00 D8).
        let bytes = [0xFF, 0xFE, b'A', 0, b'\n', 0, b'B', 0, 0x00, 0xD8];
        let error = decode(&bytes).unwrap_err();
        assert_eq!((error.position.line, error.position.column), (2, 2));
        // An odd last byte.
        assert!(decode(&[0xFF, 0xFE, b'A', 0, b'B']).is_err());
    }
}

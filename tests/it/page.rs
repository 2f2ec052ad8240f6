//! Reading the acceptance report's HTML: its keyed cells and its embedded
//! JSON. Shared by the report tests here and the browser tests (the `system`
//! target), which read Chromium's DOM dump the same way.

/// Every `data-key` value of a report: (key, full value, text shown).
pub(crate) fn keyed_values(html: &str) -> Vec<(String, Option<f64>, String)> {
    let mut found = Vec::new();
    for piece in html.split("data-key=\"").skip(1) {
        let (key, rest) = piece.split_once('"').unwrap();
        let Some(rest) = rest.strip_prefix(" data-um=\"") else {
            continue;
        };
        let (value, rest) = rest.split_once('"').unwrap();
        let text = rest[1..].split('<').next().unwrap().to_string();
        let value = (value != "null").then(|| value.parse::<f64>().unwrap());
        found.push((key.to_string(), value, text));
    }
    found
}

/// The terminal report's rounding, written out again here: two decimals, `—`.
fn shown(value: Option<f64>) -> String {
    value.map_or_else(|| "—".to_string(), |v| format!("{v:.2}"))
}

/// Checks every cell whose key starts with `prefix.` against `source` (a
/// JSON object such as `evaluate --json`'s); returns how many were checked.
pub(crate) fn check_against_json(html: &str, prefix: &str, source: &serde_json::Value) -> usize {
    let mut checked = 0;
    for (key, value, text) in keyed_values(html) {
        let Some(path) = key.strip_prefix(&format!("{prefix}.")) else {
            continue;
        };
        let pointer = format!("/{}", path.replace('.', "/"));
        let expected = source
            .pointer(&pointer)
            .unwrap_or_else(|| panic!("{key}: no {pointer} in the source JSON"));
        assert_eq!(value, expected.as_f64(), "{key}: the report's value");
        assert_eq!(text, shown(value), "{key}: the report's text");
        checked += 1;
    }
    checked
}

/// The embedded `axcomp-data` JSON of a page (or of chromium's DOM dump).
pub(crate) fn embedded_data(html: &str) -> serde_json::Value {
    let start = html
        .find("id=\"axcomp-data\">")
        .expect("the page embeds #axcomp-data");
    let json = &html[start + "id=\"axcomp-data\">".len()..];
    let json = &json[..json.find("</script>").unwrap()];
    serde_json::from_str(json).expect("#axcomp-data is JSON")
}

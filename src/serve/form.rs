//! The page's form as the server reads it: files (in memory, named by
//! their base name only) and settings.

use std::collections::BTreeMap;
use std::path::PathBuf;

use axum::extract::Multipart;
use axum::extract::multipart::MultipartError;
use axum::http::StatusCode;

/// The file fields: `file` (one, or two of one axis: API forward and
/// reverse), `after` (the re-test), `table` (the table that was active),
/// `machine` (the machine profile, as `--machine`) and `fanuc_parameters`
/// (a Fanuc parameter backup, as `--fanuc-parameters`).
const FILE_FIELDS: [&str; 5] = ["file", "after", "table", "machine", "fanuc_parameters"];

/// The settings the page sends, each at most once.
const TEXT_FIELDS: [&str; 15] = [
    "format",
    "axis",
    "standard",
    "controller",
    "mode",
    "start",
    "step",
    "count",
    "reference",
    "extrapolate",
    "linuxcnc_type",
    "diagnose",
    "limits",
    "decision",
    "fanuc_rescaled",
];

/// A file sent with the form: its name as the browser gives it, reduced
/// to the base name (the server never opens a path a client names), and
/// its content.
pub type Upload = (PathBuf, Vec<u8>);

/// One request's form.
#[derive(Debug, Default)]
pub struct Form {
    /// Per file field, the files in the order sent.
    pub files: BTreeMap<&'static str, Vec<Upload>>,
    /// The settings; an empty value is as if not sent.
    pub text: BTreeMap<&'static str, String>,
}

impl Form {
    /// Reads a multipart form; an unknown field or a setting sent twice is
    /// refused (400), and so is a form over the upload limit (413).
    pub async fn read(mut multipart: Multipart) -> Result<Form, (StatusCode, String)> {
        let refused = |error: MultipartError| (error.status(), error.body_text());
        let bad = |message: String| (StatusCode::BAD_REQUEST, message);
        let mut form = Form::default();
        while let Some(field) = multipart.next_field().await.map_err(refused)? {
            let name = field.name().unwrap_or_default().to_string();
            if let Some(&key) = FILE_FIELDS.iter().find(|k| **k == name) {
                let file_name = base_name(field.file_name().unwrap_or_default());
                let bytes = field.bytes().await.map_err(refused)?;
                form.files
                    .entry(key)
                    .or_default()
                    .push((PathBuf::from(file_name), bytes.to_vec()));
            } else if let Some(&key) = TEXT_FIELDS.iter().find(|k| **k == name) {
                let value = field.text().await.map_err(refused)?;
                let value = value.trim().to_string();
                if value.is_empty() {
                    continue;
                }
                if form.text.insert(key, value).is_some() {
                    return Err(bad(format!("the setting {key} was sent twice")));
                }
            } else {
                return Err(bad(format!("unknown form field {name:?}")));
            }
        }
        Ok(form)
    }

    /// The files of `field` (none: empty).
    pub fn files(&self, field: &str) -> &[Upload] {
        self.files.get(field).map_or(&[], Vec::as_slice)
    }

    /// The one file of `field`, if sent; two are refused.
    pub fn one_file(&self, field: &str) -> Result<Option<&Upload>, String> {
        match self.files(field) {
            [] => Ok(None),
            [one] => Ok(Some(one)),
            _ => Err(format!("one {field} file, please (two were sent)")),
        }
    }

    /// The setting `key`, if sent.
    pub fn text(&self, key: &str) -> Option<&str> {
        self.text.get(key).map(String::as_str)
    }

    /// The setting `key` as a number (`what` says which), if sent.
    pub fn number<T: std::str::FromStr>(&self, key: &str, what: &str) -> Result<Option<T>, String> {
        self.text(key)
            .map(|text| {
                text.parse()
                    .map_err(|_| format!("{key}: expected {what}, found {text:?}"))
            })
            .transpose()
    }
}

/// The last component of a name a browser sent (some send `C:\fakepath\x.rtl`).
fn base_name(name: &str) -> String {
    let base = name.rsplit(['/', '\\']).next().unwrap_or_default().trim();
    if base.is_empty() || base == "." || base == ".." {
        "upload".to_string()
    } else {
        base.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::base_name;

    #[test]
    fn only_the_base_name_of_a_sent_file_is_kept() {
        assert_eq!(base_name("C:\\fakepath\\X.rtl"), "X.rtl");
        assert_eq!(base_name("../../etc/passwd"), "passwd");
        assert_eq!(base_name(".."), "upload");
        assert_eq!(base_name(""), "upload");
        assert_eq!(base_name("sample-x.rtl"), "sample-x.rtl");
    }
}

//! `convert --json`'s object for a cross-axis table (a straightness test
//! written as "Y = F(X)") and its terminal form.

use serde::Serialize;

/// What `convert --json` prints for a cross-axis table.
#[derive(Clone, Debug, Serialize)]
pub struct CrossAxisJson {
    /// `"Y = F(X)"`.
    pub table: String,
    /// The straightness, `EYX`.
    pub error: String,
    /// The controller's name.
    pub controller: &'static str,
    /// The file written, as the user named it.
    pub output: String,
    /// Unit of the positions and values in the file.
    pub file_unit: &'static str,
    /// The ISO 230-1 reference line.
    pub reference_line: &'static str,
    /// The straightness about it.
    pub straightness_um: f64,
    /// The reference line's slope, taken out and not compensated.
    pub slope_urad: f64,
    /// Where the table is zero on the table axis.
    pub reference_mm: f64,
    /// Each point: the table axis's position and the value as in the file.
    pub points: Vec<CrossAxisPoint>,
    /// How to activate the table on the controller.
    pub activation: String,
}

/// One point of a cross-axis table, the value as the file holds it.
#[derive(Clone, Debug, Serialize)]
pub struct CrossAxisPoint {
    /// The table axis' position.
    pub position_mm: f64,
    /// The value in the file's sign.
    pub value_mm: f64,
}

/// What the terminal says besides the object.
#[derive(Clone, Debug)]
pub struct CrossAxisText {
    /// The test's file.
    pub file: String,
    /// The table axis (`X` of `EYX`).
    pub axis: String,
    /// The column axis (`Y` of `EYX`).
    pub direction: String,
    /// The moving optic's body and offset from the tool tip, mm, when taken.
    pub optics: Option<(String, [f64; 3])>,
    /// What the file's values are (`emit`: the error, or a correction).
    pub values_are: &'static str,
}

impl CrossAxisJson {
    /// The terminal form: what was written, the slope left out, the points.
    pub fn summary(&self, text: &CrossAxisText) -> String {
        let CrossAxisText {
            file,
            axis,
            direction,
            optics,
            values_are,
        } = text;
        let name = &self.error;
        let mut out = format!(
            "Cross-axis table {} ({name}: the straightness of {axis} in {direction}) from {file} for {} → {}\n",
            self.table, self.controller, self.output
        );
        out.push_str(&format!(
            "  straightness {:.2} µm ({} reference line); its slope {:.2} µrad is taken out and not compensated: it is the optics' alignment and, with the other test of the pair, squareness (predict --survey, which also takes the other axes' angles out of the slope)\n",
            self.straightness_um, self.reference_line, self.slope_urad
        ));
        if let Some((body, [x, y, z])) = optics {
            out.push_str(&format!(
                "  moving optic on the {body} (the body {axis} moves), x {x} y {y} z {z} mm from the tool tip: its offset is in the Abbe arms of the angles under that body\n",
            ));
        }
        out.push_str(&format!(
            "  zero at {axis} = {} mm (the machine's reference position unless --reference)\n\n",
            self.reference_mm
        ));
        out.push_str(&format!(
            "  {:>10}  {:>12}\n",
            format!("{axis} mm"),
            format!("{direction} mm")
        ));
        for point in &self.points {
            // To 0.1 µm as the .COM holds it; + 0.0 makes a rounded −0 print as +0.
            let shown = (point.value_mm * 1e4).round() / 1e4 + 0.0;
            out.push_str(&format!(
                "  {:>10.3}  {:>+12.4}\n",
                point.position_mm, shown
            ));
        }
        out.push_str(&format!(
            "  ({direction} values: the {values_are} in mm, as in the file)\n\n{}\n",
            self.activation
        ));
        out
    }
}

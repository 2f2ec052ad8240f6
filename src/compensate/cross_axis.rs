//! Cross-axis (straightness) compensation: a table along one axis whose
//! values move another axis, "[axis in column] = F(axis of the table)"
//! (Heidenhain MANUALplus 620 technical manual p.718, the TNC 640's family;
//! Siemens CEC with `$AN_CEC_INPUT_AXIS` ≠ `$AN_CEC_OUTPUT_AXIS`, Extended
//! Functions K3 p.248: the sag example Z = F(Y)).
//!
//! One convention inside, as for positioning tables: the value is the error
//! of the column axis (actual − nominal, mm) at the table axis's position;
//! the controller drives the column axis by −value there. Only an emitter
//! converts to its controller's sign.

use super::{CompensationTable, TableValues};

/// A cross-axis table: `table.axis` is the axis the values move (the
/// column), `table_axis` the axis whose position they are a function of.
#[derive(Clone, Debug, PartialEq)]
pub struct CrossAxisTable {
    /// The axis of the table: its positions are this axis's, mm.
    pub table_axis: String,
    /// The values (mean: a straightness has no direction), with `axis` the
    /// column axis.
    pub table: CompensationTable,
}

impl CrossAxisTable {
    /// A table of the straightness of `table_axis` in the direction of
    /// `column_axis` at evenly spaced `positions_mm`, zero at
    /// `reference_mm` (the value there taken off every point).
    ///
    /// # Example
    ///
    /// ```
    /// use axcomp::compensate::cross_axis::CrossAxisTable;
    ///
    /// // EYX: X's straightness in Y, 2 µm of bow over 0 … 200 mm.
    /// let table = CrossAxisTable::new("X", "Y", vec![0.0, 100.0, 200.0], vec![0.0, 0.002, 0.0], 0.0);
    /// assert_eq!(table.value_at(50.0), 0.001);
    /// assert_eq!(table.table.axis, "Y");
    /// ```
    pub fn new(
        table_axis: &str,
        column_axis: &str,
        positions_mm: Vec<f64>,
        values_mm: Vec<f64>,
        reference_mm: f64,
    ) -> CrossAxisTable {
        let at_reference = super::interpolate_hold(&positions_mm, &values_mm, reference_mm);
        let values = values_mm.iter().map(|v| v - at_reference).collect();
        CrossAxisTable {
            table_axis: table_axis.to_string(),
            table: CompensationTable {
                axis: column_axis.to_string(),
                kind: crate::measurement::AxisKind::Linear,
                positions: positions_mm,
                values: TableValues::Mean(values),
                reference: reference_mm,
                suggested_backlash: None,
            },
        }
    }

    /// The column axis's error the table holds at the table axis's
    /// `position_mm`: linear between points, ends held (as controllers do).
    pub fn value_at(&self, position_mm: f64) -> f64 {
        self.table
            .value_at(position_mm, crate::measurement::Direction::Up)
    }
}

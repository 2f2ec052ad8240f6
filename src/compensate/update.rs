//! Updating the table the control has (`convert --existing`): what the new
//! table keeps of the old one, and where the update is referred.
//!
//! A test taken with a table active measures the residual e; inside the
//! measured range the next table is old + e − e(r) (`add_existing_table`
//! adds the old table to the readings, `build_table` shifts), where r is the
//! reference: the existing table's own zero unless `--reference` names
//! another point. At r the update adds nothing, so the control's zero stays
//! where it was (a laser zeroed at the first target would otherwise shift the
//! whole table by e(first)). Outside the measured range the test says
//! nothing: every old point there stays with its old value (a Fanuc pitch
//! file, whose data are increments, keeps its old increments there:
//! [`KeptAs::Increments`], summed up by `emit::fanuc::update_summary`). The grid inside
//! the measured range is the new one; old points it drops and new points it
//! adds are listed, so the engineer sees a changed grid.
//!
//! Pure: no I/O. Lengths in mm (degrees on a rotary axis).

use super::{CompensateError, CompensationTable, TableValues, check_kind};
use crate::measurement::{AxisKind, Direction, Position};

/// Two positions closer than this are one point, in the axis' unit.
const SAME_POINT: f64 = 1e-6;

/// An update of `existing` by a test over `measured`, referred to
/// `reference`; positions in the axis' unit (`existing.kind`: mm, or °).
#[derive(Clone, Debug, PartialEq)]
pub struct UpdatePlan {
    /// The table the control had during the test.
    pub existing: CompensationTable,
    /// The first and last measured target.
    pub measured: (f64, f64),
    /// Where the update adds nothing.
    pub reference: f64,
    /// Whether the reference is the existing table's own zero (not `--reference`).
    pub at_existing_zero: bool,
}

/// Consecutive old points kept: first, last (in the axis' unit), how many,
/// and how much their values moved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeptRange {
    /// First point.
    pub first: f64,
    /// Last point.
    pub last: f64,
    /// Number of points.
    pub count: usize,
    /// How their values moved: not at all where the values are kept, with
    /// the point at the end of the table next to them where the increments
    /// are ([`KeptAs::Increments`]).
    pub moved: Option<Moved>,
}

/// Old points kept with their increments moved with the new table's end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Moved {
    /// The point of the new table they continue from (the table's end next to them).
    pub with: f64,
    /// The change of their values there, ↑ and ↓ (mm, or °): new − old.
    pub by: [f64; 2],
}

/// What the old points outside the measured range keep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KeptAs {
    /// Their values: a table of values per point.
    Values,
    /// Their increments: the pitch data of a Fanuc control are increments
    /// per section, updated line by line in the file (`emit::fanuc::update`),
    /// so beyond the measured range the old curve continues from the new
    /// value at the range's end.
    Increments,
}

/// The data lines of a file updated in place line by line (Fanuc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DataLines {
    /// The lines of the sections inside the measured range, which the update writes.
    pub sections: usize,
    /// Those whose value differs from the existing file's (the others are as they were).
    pub changed: usize,
}

/// What an update did, for the engineer to read; positions and values in
/// the axis' unit (`kind`: mm, or °).
#[derive(Clone, Debug, PartialEq)]
pub struct UpdateSummary {
    /// Old points outside the measured range, kept (their values, or their increments: `kept_as`), by runs.
    pub kept: Vec<KeptRange>,
    /// The same points one by one.
    pub kept_points: Vec<f64>,
    /// What they keep: their values, or (Fanuc) their increments.
    pub kept_as: KeptAs,
    /// A file updated line by line: its lines written and changed.
    pub data_lines: Option<DataLines>,
    /// The measured range.
    pub measured: (f64, f64),
    /// How many points inside it got old + residual.
    pub updated: usize,
    /// Where the update adds nothing.
    pub reference: f64,
    /// The existing table's value there (0 at its own zero).
    pub existing_at_reference: f64,
    /// Whether the reference is the existing table's own zero.
    pub at_existing_zero: bool,
    /// Old points inside the measured range that the new grid does not have.
    pub dropped: Vec<f64>,
    /// New points the old table did not have.
    pub added: Vec<f64>,
    /// The axis' kind: the unit of every position above (mm, or °).
    pub kind: AxisKind,
}

impl UpdatePlan {
    /// The plan of an update of `existing` by a test of an axis of `kind`
    /// over `targets` (in its unit), or why it cannot be made: the table
    /// and the reference must be of an axis of that kind, and the reference
    /// (`given`, else the existing table's zero) must lie inside the measured
    /// range, where the test measured the residual.
    pub fn new(
        existing: &CompensationTable,
        kind: AxisKind,
        targets: &[f64],
        given_reference: Option<Position>,
    ) -> Result<UpdatePlan, CompensateError> {
        if existing.kind != kind {
            return Err(CompensateError::KindMismatch {
                what: "existing table",
                given: existing.kind,
                measured: kind,
            });
        }
        let given_reference = given_reference
            .map(|given| check_kind("reference", given, kind))
            .transpose()?;
        let measured = (targets[0], targets[targets.len() - 1]);
        let reference = given_reference.unwrap_or(existing.reference);
        if reference < measured.0 - 1e-9 || reference > measured.1 + 1e-9 {
            return Err(CompensateError::UpdateReference {
                reference: kind.position(reference),
                given: given_reference.is_some(),
                first: kind.position(measured.0),
                last: kind.position(measured.1),
            });
        }
        Ok(UpdatePlan {
            existing: existing.clone(),
            measured,
            reference,
            at_existing_zero: given_reference.is_none(),
        })
    }

    fn inside(&self, position: f64) -> bool {
        position >= self.measured.0 - 1e-9 && position <= self.measured.1 + 1e-9
    }

    /// The existing table's value at `position`, the mean of its two
    /// directions (the value a mean table is zeroed by).
    fn existing_at(&self, position: f64) -> f64 {
        let old = &self.existing;
        (old.value_at(position, Direction::Up) + old.value_at(position, Direction::Down)) / 2.0
    }

    /// The updated table from `new` (old + residual, zero at the reference,
    /// built on the new grid): the old value at the reference put back so the
    /// update adds nothing there, the points outside the measured range
    /// replaced by the old table's values, and every old point outside the
    /// measured range added.
    pub fn apply(&self, new: CompensationTable) -> (CompensationTable, UpdateSummary) {
        let old = &self.existing;
        let at_reference = self.existing_at(self.reference);
        let bidirectional = new.values.mode() == super::TableMode::Bidirectional
            || old.values.mode() == super::TableMode::Bidirectional;
        // (position, ↑, ↓) of every point of the updated table.
        let mut rows: Vec<(f64, f64, f64)> = Vec::new();
        let mut updated = 0;
        for (index, &p) in new.positions.iter().enumerate() {
            let value = |d: Direction| {
                if self.inside(p) {
                    new.values.for_direction(d)[index] + at_reference
                } else {
                    old.value_at(p, d)
                }
            };
            updated += usize::from(self.inside(p));
            rows.push((p, value(Direction::Up), value(Direction::Down)));
        }
        let mut kept = Vec::new();
        let mut dropped = Vec::new();
        for (index, &p) in old.positions.iter().enumerate() {
            let on_new_grid = new.positions.iter().any(|q| (q - p).abs() < SAME_POINT);
            if self.inside(p) {
                if !on_new_grid {
                    dropped.push(p);
                }
                continue;
            }
            let value = |d: Direction| old.values.for_direction(d)[index];
            match rows.iter_mut().find(|row| (row.0 - p).abs() < SAME_POINT) {
                Some(row) => *row = (p, value(Direction::Up), value(Direction::Down)),
                None => rows.push((p, value(Direction::Up), value(Direction::Down))),
            }
            match kept.last_mut() {
                Some(KeptRange { last, count, .. }) if old.positions[index - 1] == *last => {
                    *last = p;
                    *count += 1;
                }
                _ => kept.push(KeptRange {
                    first: p,
                    last: p,
                    count: 1,
                    moved: None,
                }),
            }
        }
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        let added = new
            .positions
            .iter()
            .copied()
            .filter(|p| !old.positions.iter().any(|q| (q - p).abs() < SAME_POINT))
            .collect();
        let positions: Vec<f64> = rows.iter().map(|r| r.0).collect();
        let up: Vec<f64> = rows.iter().map(|r| r.1).collect();
        let values = if bidirectional {
            TableValues::Bidirectional {
                up,
                down: rows.iter().map(|r| r.2).collect(),
            }
        } else {
            TableValues::Mean(up)
        };
        let table = CompensationTable {
            positions,
            values,
            reference: self.reference,
            ..new
        };
        let summary = UpdateSummary {
            kept_points: old
                .positions
                .iter()
                .copied()
                .filter(|&p| !self.inside(p))
                .collect(),
            kept,
            kept_as: KeptAs::Values,
            data_lines: None,
            measured: self.measured,
            updated,
            reference: self.reference,
            existing_at_reference: at_reference,
            at_existing_zero: self.at_existing_zero,
            dropped,
            added,
            kind: old.kind,
        };
        (table, summary)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(positions_mm: Vec<f64>, values: TableValues) -> CompensationTable {
        CompensationTable {
            axis: "X".into(),
            kind: AxisKind::Linear,
            positions: positions_mm,
            values,
            reference: 0.0,
            suggested_backlash: None,
        }
    }

    #[test]
    fn old_points_outside_the_measured_range_stay_as_they_were() {
        // Old: −200, −100, 0, 150, 300, 400 mm; measured 0 … 300 mm on a 100 mm grid.
        let old = table(
            vec![-200.0, -100.0, 0.0, 150.0, 300.0, 400.0],
            TableValues::Mean(vec![0.02, 0.01, 0.0, 0.004, 0.006, 0.008]),
        );
        let update =
            UpdatePlan::new(&old, AxisKind::Linear, &[0.0, 100.0, 200.0, 300.0], None).unwrap();
        assert_eq!(update.reference, 0.0);
        // Built (old + residual, zero at 0 mm) on 0, 100, 200, 300.
        let new = table(
            vec![0.0, 100.0, 200.0, 300.0],
            TableValues::Mean(vec![0.0, 0.003, 0.005, 0.007]),
        );
        let (merged, summary) = update.apply(new);
        assert_eq!(
            merged.positions,
            vec![-200.0, -100.0, 0.0, 100.0, 200.0, 300.0, 400.0]
        );
        assert_eq!(
            merged.values,
            TableValues::Mean(vec![0.02, 0.01, 0.0, 0.003, 0.005, 0.007, 0.008])
        );
        assert_eq!(
            summary.kept,
            vec![
                KeptRange {
                    first: -200.0,
                    last: -100.0,
                    count: 2,
                    moved: None
                },
                KeptRange {
                    first: 400.0,
                    last: 400.0,
                    count: 1,
                    moved: None
                }
            ]
        );
        assert_eq!(summary.updated, 4);
        assert_eq!(summary.dropped, vec![150.0]);
        assert_eq!(summary.added, vec![100.0, 200.0]);
    }

    #[test]
    fn at_a_given_reference_the_update_adds_nothing() {
        // Old 0 at 0 mm and 0.004 mm at 100 mm; --reference 100: the built
        // table is zero there, the old 0.004 mm is put back.
        let old = table(
            vec![0.0, 100.0, 200.0],
            TableValues::Mean(vec![0.0, 0.004, 0.006]),
        );
        let update = UpdatePlan::new(
            &old,
            AxisKind::Linear,
            &[0.0, 100.0, 200.0],
            Some(AxisKind::Linear.position(100.0)),
        )
        .unwrap();
        let new = table(
            vec![0.0, 100.0, 200.0],
            TableValues::Mean(vec![-0.001, 0.0, 0.003]),
        );
        let (merged, summary) = update.apply(new);
        let TableValues::Mean(values) = merged.values else {
            panic!("mean")
        };
        for (got, expected) in values.iter().zip([0.003, 0.004, 0.007]) {
            assert!((got - expected).abs() < 1e-15, "{values:?}");
        }
        assert!(!summary.at_existing_zero);
        assert!((summary.existing_at_reference - 0.004).abs() < 1e-15);
        // A reference the test did not measure is refused.
        assert!(matches!(
            UpdatePlan::new(
                &old,
                AxisKind::Linear,
                &[0.0, 100.0],
                Some(AxisKind::Linear.position(150.0))
            ),
            Err(CompensateError::UpdateReference { given: true, .. })
        ));
    }

    #[test]
    fn a_rotary_update_is_refused_in_degrees_and_of_one_kind() {
        // An old rotary table over 0 … 270°, zero at 0°; the test measured
        // 90 … 270°: its zero is outside, and so is a given 300°.
        let mut old = table(
            vec![0.0, 90.0, 180.0, 270.0],
            TableValues::Mean(vec![0.0, 0.001, 0.002, 0.001]),
        );
        old.kind = AxisKind::Rotary;
        let measured = [90.0, 180.0, 270.0];
        let error = UpdatePlan::new(&old, AxisKind::Rotary, &measured, None).unwrap_err();
        assert!(
            error.to_string().starts_with(
                "the existing table is zero (its reference) at 0° is outside the measured range 90 … 270°: "
            ),
            "{error}"
        );
        let given = Some(AxisKind::Rotary.position(300.0));
        let error = UpdatePlan::new(&old, AxisKind::Rotary, &measured, given).unwrap_err();
        assert!(
            error
                .to_string()
                .starts_with("the reference 300° is outside the measured range 90 … 270°: "),
            "{error}"
        );
        // A reference in mm, or a rotary table under a linear test: refused.
        let in_mm = Some(AxisKind::Linear.position(180.0));
        assert_eq!(
            UpdatePlan::new(&old, AxisKind::Rotary, &measured, in_mm),
            Err(CompensateError::KindMismatch {
                what: "reference",
                given: AxisKind::Linear,
                measured: AxisKind::Rotary
            })
        );
        assert_eq!(
            UpdatePlan::new(&old, AxisKind::Linear, &measured, None),
            Err(CompensateError::KindMismatch {
                what: "existing table",
                given: AxisKind::Rotary,
                measured: AxisKind::Linear
            })
        );
        assert!(
            UpdatePlan::new(
                &old,
                AxisKind::Rotary,
                &measured,
                Some(AxisKind::Rotary.position(180.0))
            )
            .is_ok()
        );
    }

    #[test]
    fn a_bidirectional_old_table_keeps_both_columns_outside() {
        let old = table(
            vec![-100.0, 0.0, 100.0],
            TableValues::Bidirectional {
                up: vec![0.001, 0.0, 0.002],
                down: vec![0.003, 0.0, 0.004],
            },
        );
        let update = UpdatePlan::new(&old, AxisKind::Linear, &[0.0, 100.0], None).unwrap();
        let new = table(vec![0.0, 100.0], TableValues::Mean(vec![0.0, 0.005]));
        let (merged, _) = update.apply(new);
        assert_eq!(
            merged.values,
            TableValues::Bidirectional {
                up: vec![0.001, 0.0, 0.005],
                down: vec![0.003, 0.0, 0.005],
            }
        );
    }
}

//! A table's settings and the table that was active: the one place the
//! writers' and readers' options are made from a machine profile, and the
//! one reader of the table that was active during a test (`convert
//! --existing`, `diagnose --table`, `report --table`, the web app's `table`).

use crate::compensate::CompensationTable;
use crate::emit::{self, Controller, EmitError, EmitOptions, MachineProfile};
use crate::error::Warning;
use crate::measurement::{AxisKind, Measurement};
use crate::together::{Input, Pairing, check_together};
use crate::units::LengthUnit;

use super::{WorkflowError, read_table};

/// What a table is written as, besides the profile's axis settings.
#[derive(Clone, Copy, Debug)]
pub struct WriteAs<'a> {
    /// The controller whose file it is.
    pub controller: Controller,
    /// The unit of the test the table is made from (a Fagor 8055 file
    /// without a profile unit is in it: `MachineProfile::table_unit`).
    pub test_unit: LengthUnit,
    /// Linear (mm) or rotary (degrees).
    pub kind: AxisKind,
    /// LinuxCNC `COMP_FILE_TYPE`.
    pub linuxcnc_type: u8,
    /// Most points the machine takes, when given (else the profile's).
    pub max_points: Option<usize>,
    /// Coupled axes written the same table.
    pub also: &'a [String],
}

/// The options to write `axis`' table named `table_name` inside the file.
pub fn write_options(
    profile: &MachineProfile,
    axis: &str,
    table_name: &str,
    write: &WriteAs<'_>,
) -> Result<EmitOptions, EmitError> {
    let mut options = EmitOptions::for_axis(profile, axis, table_name)?;
    for also in write.also {
        options.axes.push(profile.axis(also)?);
    }
    options.linuxcnc_type = write.linuxcnc_type;
    options.max_points = write.max_points.or(options.max_points);
    options.machine_unit = profile.table_unit(write.controller, write.test_unit);
    options.kind = write.kind;
    Ok(options)
}

/// The options to read a table of `axis` (of `kind`) in any format; a
/// LinuxCNC table of type `linuxcnc_type` unless its numbers tell.
pub fn read_options(
    profile: &MachineProfile,
    axis: &str,
    kind: AxisKind,
    linuxcnc_type: Option<u8>,
) -> Result<EmitOptions, EmitError> {
    let mut options = EmitOptions::for_axis(profile, axis, "")?;
    options.linuxcnc_type = linuxcnc_type.unwrap_or(0);
    options.kind = kind;
    Ok(options)
}

/// The table that was active during a test, read for the test's axis.
#[derive(Clone, Debug)]
pub struct ActiveTable {
    /// The format it was read in.
    pub controller: Controller,
    /// The table, in axcomp's convention.
    pub table: CompensationTable,
    /// The doubts about the table and the test together.
    pub doubts: Vec<Warning>,
}

/// The file of an active table and the test it was active in.
#[derive(Clone, Copy, Debug)]
pub struct ActiveTableFile<'a> {
    /// Its bytes.
    pub bytes: &'a [u8],
    /// Its name, as messages give it.
    pub file: &'a str,
    /// The test's name, as messages give it.
    pub test_label: &'a str,
    /// How the front end names an axis the test does not record
    /// (`give --axis NAME (e.g. --axis X)`, the page's Axis field).
    pub how_to_name_the_axis: &'a str,
    /// `--linuxcnc-type`, when a LinuxCNC table's numbers do not tell it.
    pub linuxcnc_type: Option<u8>,
}

/// The table of `file` that was active during `test`, read for the test's
/// axis: refused when the test records no axis or when the table cannot
/// belong to it (`together`); its doubts otherwise.
pub fn active_table(
    file: ActiveTableFile<'_>,
    test: &Measurement,
    profile: &MachineProfile,
) -> Result<ActiveTable, WorkflowError> {
    let axis = recorded_axis(test, file.how_to_name_the_axis)?;
    let options = read_options(profile, axis, test.kind(), file.linuxcnc_type)?;
    let (controller, table) = read_table(
        file.bytes,
        options.clone(),
        profile,
        test.metadata.length_unit,
        file.linuxcnc_type,
    )
    .map_err(|error| WorkflowError::TableFile {
        file: file.file.to_string(),
        error,
    })?;
    let mut doubts = check_together(
        Pairing::TableOnTest,
        &Input::measurement(test, file.test_label.to_string()),
        &Input::table(&table.axis, &table.positions, file.file.to_string()),
    )?;
    doubts.extend(emit::fanuc::read_note(controller, &options));
    Ok(ActiveTable {
        controller,
        table,
        doubts,
    })
}

/// The axis `test` records, to write or read a table for: refused when the
/// file does not record it (a table for the wrong axis compensates one axis
/// with another's error); `how` says how the front end names it.
pub fn recorded_axis<'a>(test: &'a Measurement, how: &str) -> Result<&'a str, WorkflowError> {
    if test.axis_recorded() {
        return Ok(test.axis());
    }
    Err(WorkflowError::AxisNotRecorded {
        file: test.metadata.source_file.as_ref().map_or_else(
            || "the measurement".to_string(),
            |p| p.display().to_string(),
        ),
        how: how.to_string(),
    })
}

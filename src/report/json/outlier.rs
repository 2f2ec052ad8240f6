//! A suspected outlier run on the wire, in the units of its axis and of
//! `--angle-unit`: one struct per pair of units, whose field names are the
//! JSON keys and whose field types are the units those keys name.

use serde::Serialize;

use crate::evaluate::{OutlierIn, SuspectedOutlier};
use crate::measurement::{AxisKind, ByKind};
use crate::units::{AngleUnit, Arcsec, Deg, Mm, Um, Urad};

/// Declares the wire form of a suspected outlier run in one pair of units:
/// each field's name is its JSON key, its type the unit the key names.
macro_rules! outlier_json {
    (
        $(#[$doc:meta])*
        $name:ident<$position:ty, $deviation:ty> { $worst_target:ident, $offset:ident $(,)? }
    ) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Serialize)]
        pub struct $name {
            /// Run number within its direction.
            pub run: u32,
            /// `up` or `down`.
            pub direction: &'static str,
            /// Largest standardised difference from the other runs.
            pub score: f64,
            /// Where it differs most.
            pub $worst_target: $position,
            /// How much it differs there from the mean of the other runs.
            pub $offset: $deviation,
        }

        impl From<OutlierIn<$position, $deviation>> for $name {
            fn from(o: OutlierIn<$position, $deviation>) -> $name {
                $name {
                    run: o.run,
                    direction: o.direction.as_str(),
                    score: o.score,
                    $worst_target: o.worst_target,
                    $offset: o.offset,
                }
            }
        }

        impl $name {
            fn shown(&self) -> OutlierShown {
                OutlierShown {
                    run: self.run,
                    direction: self.direction,
                    score: self.score,
                    worst_target: self.$worst_target.0,
                    offset: self.$offset.0,
                }
            }
        }
    };
}

outlier_json!(
    /// A suspected outlier run of a linear axis: mm and µm.
    LinearOutlierJson<Mm, Um> { worst_target_mm, offset_um }
);

outlier_json!(
    /// A suspected outlier run of a rotary axis: ° and ″.
    ArcsecOutlierJson<Deg, Arcsec> { worst_target_deg, offset_arcsec }
);

outlier_json!(
    /// A suspected outlier run of a rotary axis: ° and µrad.
    UradOutlierJson<Deg, Urad> { worst_target_deg, offset_urad }
);

/// A suspected outlier run in the units of its axis and of `--angle-unit`,
/// the keys naming them (`worst_target_mm`, `offset_um`; `worst_target_deg`,
/// `offset_arcsec` or `offset_urad`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum OutlierJson {
    /// A linear axis: mm and µm.
    Linear(LinearOutlierJson),
    /// A rotary axis: ° and ″.
    Arcsec(ArcsecOutlierJson),
    /// A rotary axis: ° and µrad.
    Urad(UradOutlierJson),
}

/// A suspected outlier run as a report prints it: the position in its unit
/// (mm or °), the offset in the deviations' (µm, ″ or µrad).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutlierShown {
    /// Run number within its direction.
    pub run: u32,
    /// `up` or `down`.
    pub direction: &'static str,
    /// Largest standardised difference from the other runs.
    pub score: f64,
    /// Where it differs most.
    pub worst_target: f64,
    /// How much it differs there from the mean of the other runs.
    pub offset: f64,
}

impl OutlierJson {
    /// Converts a flagged run of an axis of `kind`, an angle's offset to `angle`.
    pub fn from_outlier(o: &SuspectedOutlier, kind: AxisKind, angle: AngleUnit) -> OutlierJson {
        match (o.typed(kind), angle) {
            (ByKind::Linear(o), _) => OutlierJson::Linear(o.map_offset(Mm::to_um).into()),
            (ByKind::Rotary(o), AngleUnit::Arcsec) => {
                OutlierJson::Arcsec(o.map_offset(Deg::to_arcsec).into())
            }
            (ByKind::Rotary(o), AngleUnit::Urad) => {
                OutlierJson::Urad(o.map_offset(Deg::to_urad).into())
            }
        }
    }

    /// The run as a report prints it, in its units.
    pub fn shown(&self) -> OutlierShown {
        match self {
            OutlierJson::Linear(o) => o.shown(),
            OutlierJson::Arcsec(o) => o.shown(),
            OutlierJson::Urad(o) => o.shown(),
        }
    }
}

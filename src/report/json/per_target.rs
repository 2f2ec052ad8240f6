//! One target's statistics on the wire, in the units of its axis and of
//! `--angle-unit`: one struct per pair of units, whose field names are the
//! JSON keys and whose field types are the units those keys name.

use serde::Serialize;

use crate::evaluate::{TargetIn, TargetStats};
use crate::measurement::{AxisKind, ByKind};
use crate::units::{AngleUnit, Arcsec, Deg, Mm, Um, Urad};

/// Declares the wire form of one target's statistics in one pair of units:
/// each field's name is its JSON key, its type the unit the key names.
macro_rules! per_target_json {
    (
        $(#[$doc:meta])*
        $name:ident<$position:ty, $deviation:ty> {
            $target:ident, $mean_up:ident, $mean_down:ident, $mean:ident, $s_up:ident,
            $s_down:ident, $b:ident, $r_up:ident, $r_down:ident, $r:ident $(,)?
        }
    ) => {
        $(#[$doc])*
        #[allow(non_snake_case)]
        #[derive(Clone, Copy, Debug, PartialEq, Serialize)]
        pub struct $name {
            /// Target P_i.
            pub $target: $position,
            /// Readings ↑.
            pub n_up: usize,
            /// Readings ↓.
            pub n_down: usize,
            /// x̄_i↑.
            pub $mean_up: Option<$deviation>,
            /// x̄_i↓.
            pub $mean_down: Option<$deviation>,
            /// x̄_i.
            pub $mean: Option<$deviation>,
            /// s_i↑.
            pub $s_up: Option<$deviation>,
            /// s_i↓.
            pub $s_down: Option<$deviation>,
            /// B_i (signed).
            pub $b: Option<$deviation>,
            /// R_i↑.
            pub $r_up: Option<$deviation>,
            /// R_i↓.
            pub $r_down: Option<$deviation>,
            /// R_i.
            pub $r: Option<$deviation>,
        }

        impl From<TargetIn<$position, $deviation>> for $name {
            fn from(t: TargetIn<$position, $deviation>) -> $name {
                $name {
                    $target: t.target,
                    n_up: t.n_up,
                    n_down: t.n_down,
                    $mean_up: t.mean_up,
                    $mean_down: t.mean_down,
                    $mean: t.mean,
                    $s_up: t.s_up,
                    $s_down: t.s_down,
                    $b: t.reversal,
                    $r_up: t.repeatability_up,
                    $r_down: t.repeatability_down,
                    $r: t.repeatability,
                }
            }
        }

        impl $name {
            /// The deviations with their JSON keys, in the order written.
            fn cells(&self) -> [(&'static str, Option<f64>); 9] {
                [
                    (stringify!($mean_up), self.$mean_up.map(|v| v.0)),
                    (stringify!($mean_down), self.$mean_down.map(|v| v.0)),
                    (stringify!($mean), self.$mean.map(|v| v.0)),
                    (stringify!($s_up), self.$s_up.map(|v| v.0)),
                    (stringify!($s_down), self.$s_down.map(|v| v.0)),
                    (stringify!($b), self.$b.map(|v| v.0)),
                    (stringify!($r_up), self.$r_up.map(|v| v.0)),
                    (stringify!($r_down), self.$r_down.map(|v| v.0)),
                    (stringify!($r), self.$r.map(|v| v.0)),
                ]
            }
        }
    };
}

per_target_json!(
    /// One target of a linear axis: the target in mm, deviations in µm.
    LinearTargetJson<Mm, Um> {
        target_mm, mean_up_um, mean_down_um, mean_um, s_up_um, s_down_um, B_um, R_up_um,
        R_down_um, R_um,
    }
);

per_target_json!(
    /// One target of a rotary axis: the target in °, deviations in ″.
    ArcsecTargetJson<Deg, Arcsec> {
        target_deg, mean_up_arcsec, mean_down_arcsec, mean_arcsec, s_up_arcsec,
        s_down_arcsec, B_arcsec, R_up_arcsec, R_down_arcsec, R_arcsec,
    }
);

per_target_json!(
    /// One target of a rotary axis: the target in °, deviations in µrad.
    UradTargetJson<Deg, Urad> {
        target_deg, mean_up_urad, mean_down_urad, mean_urad, s_up_urad, s_down_urad,
        B_urad, R_up_urad, R_down_urad, R_urad,
    }
);

/// Statistics at one target in the units of its axis and of `--angle-unit`;
/// each form's keys name its units (`target_mm`, `mean_up_um`;
/// `target_deg`, `mean_up_arcsec` or `mean_up_urad`).
///
/// A rotary target becomes the rotary wire form:
/// ```
/// use axcomp::evaluate::TargetIn;
/// use axcomp::report::json::ArcsecTargetJson;
/// use axcomp::units::Deg;
/// fn wire(t: TargetIn<Deg>) -> ArcsecTargetJson {
///     t.map_deviations(Deg::to_arcsec).into()
/// }
/// ```
/// and cannot become the linear one (`target_mm`, `mean_up_um`), neither
/// with its deviations in ″
/// ```compile_fail
/// use axcomp::evaluate::TargetIn;
/// use axcomp::report::json::LinearTargetJson;
/// use axcomp::units::Deg;
/// fn wire(t: TargetIn<Deg>) -> LinearTargetJson {
///     t.map_deviations(Deg::to_arcsec).into()
/// }
/// ```
/// nor with its degrees taken for millimetres:
/// ```compile_fail
/// use axcomp::evaluate::TargetIn;
/// use axcomp::report::json::LinearTargetJson;
/// use axcomp::units::{Deg, Mm};
/// fn wire(t: TargetIn<Deg>) -> LinearTargetJson {
///     t.map_deviations(Mm::to_um).into()
/// }
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum PerTargetJson {
    /// A linear axis: mm and µm.
    Linear(LinearTargetJson),
    /// A rotary axis: ° and ″.
    Arcsec(ArcsecTargetJson),
    /// A rotary axis: ° and µrad.
    Urad(UradTargetJson),
}

impl PerTargetJson {
    /// Converts one target's statistics of a linear axis to µm.
    pub fn from_stats(t: &TargetStats) -> PerTargetJson {
        PerTargetJson::from_stats_of(t, AxisKind::Linear, AngleUnit::default())
    }

    /// Converts one target's statistics to µm, or `angle` (″, µrad) on a rotary axis.
    pub fn from_stats_of(t: &TargetStats, kind: AxisKind, angle: AngleUnit) -> PerTargetJson {
        match (t.typed(kind), angle) {
            (ByKind::Linear(t), _) => PerTargetJson::Linear(t.map_deviations(Mm::to_um).into()),
            (ByKind::Rotary(t), AngleUnit::Arcsec) => {
                PerTargetJson::Arcsec(t.map_deviations(Deg::to_arcsec).into())
            }
            (ByKind::Rotary(t), AngleUnit::Urad) => {
                PerTargetJson::Urad(t.map_deviations(Deg::to_urad).into())
            }
        }
    }

    /// The target, in its unit (mm, or ° on a rotary axis).
    pub fn target(&self) -> f64 {
        match self {
            PerTargetJson::Linear(t) => t.target_mm.0,
            PerTargetJson::Arcsec(t) => t.target_deg.0,
            PerTargetJson::Urad(t) => t.target_deg.0,
        }
    }

    /// Readings ↑ and ↓.
    pub fn readings(&self) -> (usize, usize) {
        match self {
            PerTargetJson::Linear(t) => (t.n_up, t.n_down),
            PerTargetJson::Arcsec(t) => (t.n_up, t.n_down),
            PerTargetJson::Urad(t) => (t.n_up, t.n_down),
        }
    }

    /// The nine deviations with their JSON keys, in the order written:
    /// x̄↑, x̄↓, x̄, s↑, s↓, B, R↑, R↓, R, in µm (″, µrad).
    pub fn cells(&self) -> [(&'static str, Option<f64>); 9] {
        match self {
            PerTargetJson::Linear(t) => t.cells(),
            PerTargetJson::Arcsec(t) => t.cells(),
            PerTargetJson::Urad(t) => t.cells(),
        }
    }
}

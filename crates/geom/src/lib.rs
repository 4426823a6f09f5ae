//! tezgah-geom: the geometric vocabulary shared by every stage of tezgah.
//!
//! It sits at the bottom of the crate stack: the G-code interpreter emits [`Move`]s built from
//! these types, and the planner, kinematics and CAM consume them without knowing about G-code.
//! The curve layer ([`Curve`] and its implementations, [`ArcLengthMap`], [`fit`],
//! [`deviation`]) is what the path builder turns moves into; the surface layer ([`NurbsSurface`])
//! is what CAM machines.

pub mod arc;
pub mod arclen;
mod banded;
pub mod basis;
pub mod bezier;
mod bezier_spans;
pub mod curvature;
pub mod curve;
pub mod deviation;
pub mod error;
pub mod fit;
pub mod line;
pub mod moves;
pub mod nurbs;
pub mod pose;
pub mod quintic;
pub mod surface;
pub mod trim;

pub use arc::{Arc, Helix};
pub use arclen::{ArcLengthCursor, ArcLengthMap, ArcPosition, PrebuiltArcLength};
pub use bezier::Bezier;
pub use curve::{Curve, Vec3};
pub use error::CurveError;
pub use line::Line;
pub use moves::{
    ArcMove, FeedMode, Move, MoveKind, NurbsMove, PathMode, Plane, StopKind, SyncedMove,
    ToolControl, Turn,
};
pub use nurbs::{BoundingBox, Nurbs};
pub use pose::{Axis, Pose};
pub use quintic::{Quintic, State};
pub use surface::{
    ClosestPoint, FundamentalForms, NurbsSurface, PrincipalCurvatures, SurfaceDerivs, SurfaceError,
};
pub use trim::Trimmed;

//! STEP input (ISO 10303-21 exchange structure, AP203/AP214 geometry): the first stage of CAM,
//! reading the free-form faces to machine as `tezgah-geom` NURBS surfaces in mm.
//!
//! `lexer` → `exchange` (schema-free instances by `#id`) → `entity` (typed attribute access
//! with errors naming `#id`, type and line) → `units`, `geometry` (+ `conic`) → `topology`
//! (faces, loops, edges; surfaces by kind: B-spline, plane, `revolved`, `swept`) → `pcurve`
//! (trimming curves in (u, v)) → `model`.

mod conic;
mod entity;
mod error;
mod exchange;
mod face_region;
mod geometry;
mod lexer;
mod model;
mod pcurve;
mod revolved;
mod swept;
mod topology;
mod units;

use std::path::Path;

use tezgah_geom::{Nurbs, NurbsSurface};

pub use error::{At, StepError};
pub use face_region::FaceRegionError;
pub use model::{
    Bound, BoundEdge, BoundKind, Face, LengthUnit, PCurve, ReadOptions, StepModel, Uv,
    UNTRIMMED_SAMPLES_PER_EDGE,
};
pub use pcurve::PCURVE_TOLERANCE_MM;

use entity::Resolve;
use exchange::Exchange;
use geometry::Geometry;

/// Reads a STEP file's text: every face of its solids (`MANIFOLD_SOLID_BREP`,
/// `BREP_WITH_VOIDS`) and shell-based surface models, or of its shells when it has neither.
pub fn read(text: &str) -> Result<StepModel, StepError> {
    StepFile::parse(text.as_bytes())?.model()
}

/// [`read`] with options (e.g. leaving out faces on unsupported surfaces).
pub fn read_with(text: &str, options: &ReadOptions) -> Result<StepModel, StepError> {
    StepFile::parse(text.as_bytes())?.model_with(options)
}

/// [`read`] on a file; errors name the file. The bytes need not be UTF-8 (STEP strings may be
/// ISO 8859-1); only names are text, and they are read lossily.
pub fn read_file(path: impl AsRef<Path>) -> Result<StepModel, StepError> {
    read_file_with(path, &ReadOptions::default())
}

/// [`read_file`] with options.
pub fn read_file_with(
    path: impl AsRef<Path>,
    options: &ReadOptions,
) -> Result<StepModel, StepError> {
    let path = path.as_ref();
    let wrap = |e: StepError| StepError::File {
        path: path.display().to_string(),
        source: Box::new(e),
    };
    let bytes = std::fs::read(path).map_err(|e| StepError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    StepFile::parse(&bytes)
        .and_then(|f| f.model_with(options))
        .map_err(wrap)
}

/// A parsed exchange structure, for reading single entities (a bare surface, an edge curve)
/// as well as the whole model.
#[derive(Debug, Clone)]
pub struct StepFile {
    ex: Exchange,
    unit: LengthUnit,
    /// Radians per plane angle unit.
    angle: f64,
}

impl StepFile {
    /// Parses the exchange structure and finds the length unit.
    pub fn parse(bytes: &[u8]) -> Result<Self, StepError> {
        let ex = exchange::parse(bytes)?;
        let unit = units::length_unit(&ex)?;
        let angle = units::plane_angle(&ex)?;
        Ok(StepFile { ex, unit, angle })
    }

    pub fn unit(&self) -> &LengthUnit {
        &self.unit
    }

    /// Number of entity instances in the DATA section(s).
    pub fn instance_count(&self) -> usize {
        self.ex.instances.len()
    }

    /// The faces of the file's bodies (see [`read`]).
    pub fn model(&self) -> Result<StepModel, StepError> {
        self.model_with(&ReadOptions::default())
    }

    /// The faces of the file's bodies, with options.
    pub fn model_with(&self, options: &ReadOptions) -> Result<StepModel, StepError> {
        let (faces, skipped) = topology::faces(&self.geometry(), options.skip_unsupported_faces)?;
        Ok(StepModel {
            faces,
            unit: self.unit.clone(),
            schemas: self.ex.schemas.clone(),
            skipped,
        })
    }

    /// The B-spline surface `#id` (plain or rational), in mm.
    pub fn surface(&self, id: u64) -> Result<NurbsSurface, StepError> {
        let e = self.ex.entity(id).ok_or(StepError::Missing { id })?;
        if !geometry::is_bspline(e.instance, &geometry::BSPLINE_SURFACES) {
            return Err(StepError::Unsupported {
                at: e.at(),
                role: "a B-spline surface".to_string(),
            });
        }
        self.geometry().bspline_surface(&e)
    }

    /// The curve `#id` (a B-spline, plain or rational, or a surface curve's 3-D curve), in mm.
    pub fn curve(&self, id: u64) -> Result<Nurbs, StepError> {
        let e = self.ex.entity(id).ok_or(StepError::Missing { id })?;
        self.geometry().curve(&e, 0)
    }

    fn geometry(&self) -> Geometry<'_> {
        Geometry {
            ex: &self.ex,
            mm: self.unit.mm,
            angle: self.angle,
        }
    }
}

/// For the fuzz target: reads arbitrary bytes through every stage; errors are expected, a
/// panic is a bug.
#[doc(hidden)]
pub fn fuzz(bytes: &[u8]) {
    if let Ok(file) = StepFile::parse(bytes) {
        let _ = file.model();
        let _ = file.model_with(&ReadOptions {
            skip_unsupported_faces: true,
        });
        for id in file.ex.ids().into_iter().take(64) {
            let _ = file.surface(id);
            let _ = file.curve(id);
        }
    }
}

//! STEP input: the STEP excerpt of Can (2010, Appendix A) with its golden boundary curve,
//! hand-written files with closed-form answers (a plane face, units), and the exact error
//! texts for unknown entities, dangling references, bad knot counts and units.

use std::path::PathBuf;

use tezgah_cam::step::{self, BoundKind, StepError, StepFile};
use tezgah_geom::{Curve, Vec3};

fn excerpt() -> String {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/001_surface_excerpt.stp");
    std::fs::read_to_string(path).unwrap()
}

/// The excerpt with its elision lines (`.....`, `.`) blanked, so line numbers are kept.
fn excerpt_without_elisions() -> String {
    excerpt()
        .lines()
        .map(|l| {
            if !l.trim().is_empty() && l.trim().chars().all(|c| c == '.') {
                ""
            } else {
                l
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

const HEAD: &str = "ISO-10303-21;
HEADER;
FILE_DESCRIPTION(('test'),'2;1');
FILE_NAME('t.stp','2026-01-01T00:00:00',(''),(''),'','','');
FILE_SCHEMA(('AUTOMOTIVE_DESIGN'));
ENDSEC;
DATA;
";

fn file(data: &str) -> String {
    format!("{HEAD}{data}\nENDSEC;\nEND-ISO-10303-21;\n")
}

/// A 20 × 10 rectangle in the plane z = 5 (origin (1, 2, 5)), as a face of a shell-based
/// surface model bounded by four lines, in the length unit `unit` (line 8 on).
fn plane_file(unit: &str, face_sense: &str) -> String {
    file(&format!(
        "#1 = SHELL_BASED_SURFACE_MODEL('',(#2));
#2 = OPEN_SHELL('',(#3));
#3 = ADVANCED_FACE('',(#4),#30,{face_sense});
#4 = FACE_OUTER_BOUND('',#5,.T.);
#5 = EDGE_LOOP('',(#6,#7,#8,#9));
#6 = ORIENTED_EDGE('',*,*,#10,.T.);
#7 = ORIENTED_EDGE('',*,*,#11,.T.);
#8 = ORIENTED_EDGE('',*,*,#12,.T.);
#9 = ORIENTED_EDGE('',*,*,#13,.F.);
#10 = EDGE_CURVE('',#20,#21,#40,.T.);
#11 = EDGE_CURVE('',#21,#22,#40,.T.);
#12 = EDGE_CURVE('',#22,#23,#40,.T.);
#13 = EDGE_CURVE('',#20,#23,#40,.T.);
#20 = VERTEX_POINT('',#24);
#21 = VERTEX_POINT('',#25);
#22 = VERTEX_POINT('',#26);
#23 = VERTEX_POINT('',#27);
#24 = CARTESIAN_POINT('',(1.,2.,5.));
#25 = CARTESIAN_POINT('',(21.,2.,5.));
#26 = CARTESIAN_POINT('',(21.,12.,5.));
#27 = CARTESIAN_POINT('',(1.,12.,5.));
#30 = PLANE('',#31);
#31 = AXIS2_PLACEMENT_3D('',#32,#33,#34);
#32 = CARTESIAN_POINT('',(0.,0.,5.));
#33 = DIRECTION('',(0.,0.,1.));
#34 = DIRECTION('',(1.,0.,0.));
#40 = LINE('',#32,#41);
#41 = VECTOR('',#33,1.);
#50 = ( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNIT_ASSIGNED_CONTEXT((#51,#52))
  REPRESENTATION_CONTEXT('',''));
#51 = {unit};
#52 = ( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) );"
    ))
}

const MM: &str = "( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )";

#[test]
fn excerpt_as_printed_is_a_syntax_error_at_the_elision() {
    let e = step::read(&excerpt()).unwrap_err();
    assert_eq!(e.to_string(), "line 69: a number needs digits");
}

#[test]
fn excerpt_units_and_missing_shell() {
    let text = excerpt_without_elisions();
    let f = StepFile::parse(text.as_bytes()).unwrap();
    assert_eq!(f.unit().name, "MILLI METRE");
    assert_eq!(f.unit().mm, 1.0);
    // 41 control points + 35 other instances survive the elisions (#1–#35, #105–#145).
    assert_eq!(f.instance_count(), 35 + 41);
    let e = f.model().unwrap_err();
    assert_eq!(
        e.to_string(),
        "#116 SHELL_BASED_SURFACE_MODEL (line 91): refers to #162, which the file does not define"
    );
}

#[test]
fn excerpt_surface_reports_the_corrupted_multiplicities_then_the_elided_points() {
    let text = excerpt_without_elisions();
    let f = StepFile::parse(text.as_bytes()).unwrap();
    assert_eq!(
        f.surface(1).unwrap_err().to_string(),
        "#1 B_SPLINE_SURFACE_WITH_KNOTS (line 15): v multiplicities list has 8 entries but v knots has 9"
    );
    // The excerpt's v multiplicities do not add up (Σ ≠ n + p + 1): the v list must be
    // (4,1,1,1,1,1,1,1,4); with it repaired, the first control point the excerpt elided (row 2,
    // column 8) is the error.
    let repaired = text.replacen(
        "( 4, 1, 1, 1, 1, 1, 1, 4 ),\n  ( 0.0",
        "( 4, 1, 1, 1, 1, 1, 1, 1, 4 ),\n  ( 0.0",
        1,
    );
    let repaired = repaired.replacen(
        "( 4, 1, 1, 1, 1, 1, 1, 4 ),\n  ( 4, 1, 1, 1, 1, 1, 1, 4 )",
        "( 4, 1, 1, 1, 1, 1, 1, 4 ),\n  ( 4, 1, 1, 1, 1, 1, 1, 1, 4 )",
        1,
    );
    let f = StepFile::parse(repaired.as_bytes()).unwrap();
    assert_eq!(
        f.surface(1).unwrap_err().to_string(),
        "#1 B_SPLINE_SURFACE_WITH_KNOTS (line 15): refers to #40, which the file does not define"
    );
}

#[test]
fn excerpt_boundary_curve_matches_the_golden_values() {
    // #114 is the u = 0 boundary reversed: C(t) = S(0, 1 − t); Cox–de Boor on the
    // repaired data gives S(0, v) to 9 decimals. #121 (the curve's first point) lost digits in
    // transcription (≈ 2e-9 mm), hence 1e-8.
    let f = StepFile::parse(excerpt_without_elisions().as_bytes()).unwrap();
    let c = f.curve(114).unwrap();
    assert_eq!(c.degree(), 3);
    assert_eq!(c.domain(), (0.0, 1.0));
    let golden = [
        (0.0, 0.0, 160.0, -3.0e-15),
        (0.1, 12.973465610, 160.0, 0.257625035),
        (0.25, 32.400423760, 160.0, -0.194959050),
        (0.5, 64.716606570, 160.0, -2.609006400),
        (0.75, 97.127191700, 160.0, -1.961494260),
        (0.9, 116.543372760, 160.0, -0.833556840),
        (1.0, 129.475449392, 160.0, 0.0),
    ];
    for (v, x, y, z) in golden {
        let p = c.point(1.0 - v);
        assert!((p - Vec3::new(x, y, z)).amax() < 1e-8, "v = {v}: {p:?}");
    }
}

#[test]
fn plane_face_bounded_by_lines() {
    let m = step::read(&plane_file(MM, ".T.")).unwrap();
    assert_eq!(m.faces.len(), 1);
    let f = &m.faces[0];
    assert_eq!(f.id, 3);
    assert!(f.same_sense);
    // The bilinear patch over the loop's extent, with the plane's own parameters (mm from the
    // plane's origin (0, 0, 5) along x and y).
    assert_eq!(f.surface.degrees(), (1, 1));
    assert_eq!(f.surface.domain_u(), (1.0, 21.0));
    assert_eq!(f.surface.domain_v(), (2.0, 12.0));
    assert!((f.surface.point(7.0, 4.5) - Vec3::new(7.0, 4.5, 5.0)).amax() < 1e-12);
    let n = f.surface.derivs(7.0, 4.5);
    assert_eq!(n.su.cross(&n.sv).normalize(), Vec3::z());
    assert!(f.is_untrimmed(1e-9));
    let b = &f.bounds[0];
    assert!(b.outer && b.orientation);
    let BoundKind::Edges(edges) = &b.kind else {
        panic!("an edge loop")
    };
    // The loop runs (1,2) → (21,2) → (21,12) → (1,12) → (1,2); the last edge is used reversed.
    let corners =
        [(1.0, 2.0), (21.0, 2.0), (21.0, 12.0), (1.0, 12.0)].map(|(x, y)| Vec3::new(x, y, 5.0));
    for (k, e) in edges.iter().enumerate() {
        assert_eq!(e.start(), corners[k]);
        assert_eq!(e.end(), corners[(k + 1) % 4]);
    }
    assert!(!edges[3].forward);
    // Plain LINE edges, no pcurves in the file: on a plane they are projected, exactly. The
    // plane's parameters here are x and y (origin (0, 0, 5), x axis along x).
    let uv = b.uv_polygon(1).unwrap();
    let corners: Vec<(f64, f64)> = uv.iter().map(|p| (p.u, p.v)).collect();
    assert_eq!(
        corners,
        [(1.0, 2.0), (21.0, 2.0), (21.0, 12.0), (1.0, 12.0)]
    );
    assert_eq!(edges[3].polyline(2)[1], Vec3::new(1.0, 7.0, 5.0));
}

#[test]
fn face_sense_and_oriented_faces_combine() {
    let m = step::read(&plane_file(MM, ".F.")).unwrap();
    assert!(!m.faces[0].same_sense);
    let flipped = plane_file(MM, ".F.").replace(
        "#2 = OPEN_SHELL('',(#3));",
        "#2 = OPEN_SHELL('',(#60));\n#60 = ORIENTED_FACE('',*,#3,.F.);",
    );
    assert!(step::read(&flipped).unwrap().faces[0].same_sense);
}

#[test]
fn lengths_are_converted_to_mm() {
    let metre = "( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT($,.METRE.) )";
    let m = step::read(&plane_file(metre, ".T.")).unwrap();
    assert_eq!(m.unit.name, "METRE");
    assert_eq!(m.unit.mm, 1000.0);
    assert_eq!(m.faces[0].surface.domain_u(), (1000.0, 21000.0));
    let p = m.faces[0].surface.point(1000.0, 2000.0);
    assert!((p - Vec3::new(1000.0, 2000.0, 5000.0)).amax() < 1e-9);
    let centi = "( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.CENTI.,.METRE.) )";
    assert_eq!(step::read(&plane_file(centi, ".T.")).unwrap().unit.mm, 10.0);
    let foot = "( CONVERSION_BASED_UNIT('FOOT',#53) LENGTH_UNIT() NAMED_UNIT(#54) );
#53 = LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(12.),#55);
#54 = DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.);
#55 = ( CONVERSION_BASED_UNIT('INCH',#56) LENGTH_UNIT() NAMED_UNIT(#54) );
#56 = LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#57);
#57 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )";
    let m = step::read(&plane_file(foot, ".T.")).unwrap();
    assert_eq!(m.unit.name, "FOOT");
    assert!((m.unit.mm - 304.8).abs() < 1e-12);
    // Without any unit context, millimetres are assumed and said so.
    let bare = plane_file(MM, ".T.").replace("GLOBAL_UNIT_ASSIGNED_CONTEXT((#51,#52))", "");
    assert_eq!(step::read(&bare).unwrap().unit.name, "mm (assumed)");
}

#[test]
fn unit_errors() {
    let second = "( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT($,.SECOND.) )";
    assert_eq!(
        step::read(&plane_file(second, ".T."))
            .unwrap_err()
            .to_string(),
        "#51 LENGTH_UNIT+NAMED_UNIT+SI_UNIT (line 38): length unit .SECOND. is not a length"
    );
    let loop_unit = "( CONVERSION_BASED_UNIT('LOOP',#53) LENGTH_UNIT() NAMED_UNIT(*) );
#53 = LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(2.),#51)";
    assert_eq!(
        step::read(&plane_file(loop_unit, ".T.")).unwrap_err().to_string(),
        "#51 CONVERSION_BASED_UNIT+LENGTH_UNIT+NAMED_UNIT (line 38): unit conversions chained deeper than 8"
    );
    let two = plane_file(MM, ".T.").replace(
        "#52 = ( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) );",
        "#52 = ( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) );
#60 = ( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNIT_ASSIGNED_CONTEXT((#61)) REPRESENTATION_CONTEXT('',''));
#61 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT($,.METRE.) );",
    );
    assert_eq!(
        step::read(&two).unwrap_err().to_string(),
        "the file has several length units: MILLI METRE and METRE"
    );
}

#[test]
fn unsupported_entities_are_named() {
    let offset = plane_file(MM, ".T.").replace(
        "#30 = PLANE('',#31);",
        "#30 = OFFSET_SURFACE('',#40,2.,.F.);",
    );
    assert_eq!(
        step::read(&offset).unwrap_err().to_string(),
        "#30 OFFSET_SURFACE (line 29): unsupported entity, met as the surface of #3 ADVANCED_FACE (line 10)"
    );
    // A cylinder is read, its extent taken from the loop — which here lies in one plane
    // across the axis and so spans no area of the cylinder.
    let cyl = plane_file(MM, ".T.").replace(
        "#30 = PLANE('',#31);",
        "#30 = CYLINDRICAL_SURFACE('',#31,4.);",
    );
    assert_eq!(
        step::read(&cyl).unwrap_err().to_string(),
        "#30 CYLINDRICAL_SURFACE (line 29): the face's bounds do not span an area on it"
    );
    let hyperbola = plane_file(MM, ".T.").replace(
        "#11 = EDGE_CURVE('',#21,#22,#40,.T.);",
        "#11 = EDGE_CURVE('',#21,#22,#42,.T.);\n#42 = HYPERBOLA('',#31,3.,2.);",
    );
    assert_eq!(
        step::read(&hyperbola).unwrap_err().to_string(),
        "#42 HYPERBOLA (line 19): unsupported entity, met as an edge curve"
    );
    let poly = plane_file(MM, ".T.").replace(
        "#5 = EDGE_LOOP('',(#6,#7,#8,#9));",
        "#5 = POLY_LOOP('',(#24,#25,#26));",
    );
    assert_eq!(
        step::read(&poly).unwrap_err().to_string(),
        "#5 POLY_LOOP (line 12): unsupported entity, met as the loop of #4 FACE_OUTER_BOUND (line 11)"
    );
    let nothing = file("#1 = CARTESIAN_POINT('',(0.,0.,0.));");
    assert_eq!(step::read(&nothing).unwrap_err(), StepError::NoShape);
}

#[test]
fn dangling_references_are_named() {
    let text = plane_file(MM, ".T.").replace("#26 = CARTESIAN_POINT('',(21.,12.,5.));\n", "");
    assert_eq!(
        step::read(&text).unwrap_err().to_string(),
        "#22 VERTEX_POINT (line 23): refers to #26, which the file does not define"
    );
}

const SURFACE: &str = "#1 = SHELL_BASED_SURFACE_MODEL('',(#2));
#2 = OPEN_SHELL('',(#3));
#3 = ADVANCED_FACE('',(),#4,.T.);
#4 = B_SPLINE_SURFACE_WITH_KNOTS('',1,1,((#10,#11),(#12,#13)),.UNSPECIFIED.,.F.,.F.,.F.,
  (2,2),(2,2),(0.,1.),(0.,2.),.UNSPECIFIED.);
#10 = CARTESIAN_POINT('',(0.,0.,0.));
#11 = CARTESIAN_POINT('',(0.,10.,0.));
#12 = CARTESIAN_POINT('',(10.,0.,0.));
#13 = CARTESIAN_POINT('',(10.,10.,3.));";

#[test]
fn bilinear_b_spline_face() {
    let m = step::read(&file(SURFACE)).unwrap();
    let s = &m.faces[0].surface;
    assert_eq!(s.domain_v(), (0.0, 2.0));
    // The bilinear interpolant of the corners: z = 3·u·(v/2) at (u, v).
    assert!((s.point(0.5, 1.0) - Vec3::new(5.0, 5.0, 0.75)).amax() < 1e-12);
    assert!(m.faces[0].bounds.is_empty());
}

#[test]
fn knot_errors() {
    let bad_sum =
        file(SURFACE).replace("(2,2),(2,2),(0.,1.),(0.,2.)", "(2,2),(2,1),(0.,1.),(0.,2.)");
    assert_eq!(
        step::read(&bad_sum).unwrap_err().to_string(),
        "#4 B_SPLINE_SURFACE_WITH_KNOTS (line 11): v multiplicities sum to 3, but 2 control points of degree 1 need 4"
    );
    let decreasing = file(SURFACE).replace("(0.,1.),(0.,2.)", "(0.,1.),(2.,0.)");
    assert!(step::read(&decreasing)
        .unwrap_err()
        .to_string()
        .starts_with("#4 B_SPLINE_SURFACE_WITH_KNOTS (line 11): v direction: "));
    let degree = file(SURFACE).replace(
        "B_SPLINE_SURFACE_WITH_KNOTS('',1,1,",
        "B_SPLINE_SURFACE_WITH_KNOTS('',1,99,",
    );
    assert_eq!(
        step::read(&degree).unwrap_err().to_string(),
        "#4 B_SPLINE_SURFACE_WITH_KNOTS (line 11): v_degree is 99; tezgah reads degrees 1 to 15"
    );
    let ragged = file(SURFACE).replace("((#10,#11),(#12,#13))", "((#10,#11),(#12))");
    assert_eq!(
        step::read(&ragged).unwrap_err().to_string(),
        "#4 B_SPLINE_SURFACE_WITH_KNOTS (line 11): control point row 2 has 1 points, row 1 has 2"
    );
    let short = file(SURFACE)
        .replace(",.UNSPECIFIED.);\n#10", ");\n#10")
        .replace("(2,2),(2,2),(0.,1.),(0.,2.)", "(2,2),(2,2),(0.,1.)");
    assert_eq!(
        step::read(&short).unwrap_err().to_string(),
        "#4 B_SPLINE_SURFACE_WITH_KNOTS (line 11): B_SPLINE_SURFACE_WITH_KNOTS has 11 attributes, v_knots (attribute 12) is missing"
    );
}

#[test]
fn read_file_names_the_file() {
    let dir = std::env::temp_dir().join(format!("tezgah-step-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.stp");
    std::fs::write(&path, file("#1 = A(;")).unwrap();
    let e = step::read_file(&path).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "{}: line 8: expected a parameter, found `;`",
            path.display()
        )
    );
    let missing = dir.join("missing.stp");
    assert!(step::read_file(&missing)
        .unwrap_err()
        .to_string()
        .starts_with(&format!("{}: ", missing.display())));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn crlf_line_ends_and_comments_read_the_same() {
    let lf = plane_file(MM, ".T.");
    let crlf = lf
        .replace('\n', "\r\n")
        .replace("DATA;", "DATA; /* a comment\r\n over two lines */");
    assert_eq!(step::read(&crlf).unwrap(), step::read(&lf).unwrap());
    let e = step::read(&crlf.replace("#26 = CARTESIAN_POINT('',(21.,12.,5.));", "")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "#22 VERTEX_POINT (line 24): refers to #26, which the file does not define"
    );
}

#[test]
fn a_pcurve_off_its_edge_is_dropped() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/plate_with_holes.stp");
    let text = std::fs::read_to_string(path).unwrap();
    let hole_pcurves = |text: &str| -> Vec<bool> {
        let m = step::read(text).unwrap();
        m.faces[0]
            .bounds
            .iter()
            .map(|b| match &b.kind {
                BoundKind::Edges(e) => e.iter().all(|e| e.pcurve.is_some()),
                BoundKind::Vertex(_) => false,
            })
            .collect()
    };
    assert_eq!(hole_pcurves(&text), [true, true, true]);
    // The circular hole's 2-D circle (#103) given radius 10.001 instead of 10: mapped through
    // the plane it misses the 3-D edge by 1e-3 mm > PCURVE_TOLERANCE_MM.
    assert!(text.contains("#103 = CIRCLE('',#104,10.);"));
    let off = text.replace(
        "#103 = CIRCLE('',#104,10.);",
        "#103 = CIRCLE('',#104,10.001);",
    );
    assert_eq!(hole_pcurves(&off), [true, false, true]);
    const { assert!(step::PCURVE_TOLERANCE_MM < 1e-3) };
}

/// A face whose one loop runs along pieces of a B-spline polyline (0,0)→(10,0)→(10,10)→(0,10)
/// and back along a line: the edge's vertices sit inside the curve's domain.
fn interior_vertices_file(same_sense: &str, start: &str, end: &str) -> String {
    file(&format!(
        "#1 = SHELL_BASED_SURFACE_MODEL('',(#2));
#2 = OPEN_SHELL('',(#3));
#3 = ADVANCED_FACE('',(#4),#30,.T.);
#4 = FACE_BOUND('',#5,.T.);
#5 = EDGE_LOOP('',(#6,#7));
#6 = ORIENTED_EDGE('',*,*,#10,.T.);
#7 = ORIENTED_EDGE('',*,*,#11,.T.);
#10 = EDGE_CURVE('',{start},{end},#40,{same_sense});
#11 = EDGE_CURVE('',{end},{start},#41,.T.);
#20 = VERTEX_POINT('',#24);
#21 = VERTEX_POINT('',#25);
#24 = CARTESIAN_POINT('',(5.,0.,0.));
#25 = CARTESIAN_POINT('',(5.,10.,0.));
#30 = PLANE('',#31);
#31 = AXIS2_PLACEMENT_3D('',#32,$,$);
#32 = CARTESIAN_POINT('',(0.,0.,0.));
#40 = B_SPLINE_CURVE_WITH_KNOTS('',1,(#42,#43,#44,#45),.POLYLINE_FORM.,.F.,.F.,(2,1,1,2),
  (0.,1.,2.,3.),.UNSPECIFIED.);
#41 = LINE('',#24,#46);
#42 = CARTESIAN_POINT('',(0.,0.,0.));
#43 = CARTESIAN_POINT('',(10.,0.,0.));
#44 = CARTESIAN_POINT('',(10.,10.,0.));
#45 = CARTESIAN_POINT('',(0.,10.,0.));
#46 = VECTOR('',#47,1.);
#47 = DIRECTION('',(0.,1.,0.));"
    ))
}

#[test]
fn b_spline_edges_are_cut_at_their_vertices() {
    let m = step::read(&interior_vertices_file(".T.", "#20", "#21")).unwrap();
    let f = &m.faces[0];
    let BoundKind::Edges(edges) = &f.bounds[0].kind else {
        panic!("an edge loop")
    };
    // (5,0) is t = 0.5 on the polyline, (5,10) is t = 2.5.
    assert!((edges[0].curve.domain().0 - 0.5).abs() < 1e-12);
    assert!((edges[0].curve.domain().1 - 2.5).abs() < 1e-12);
    assert!(edges[0].forward);
    assert!((edges[0].start() - Vec3::new(5.0, 0.0, 0.0)).norm() < 1e-12);
    assert!((edges[0].end() - Vec3::new(5.0, 10.0, 0.0)).norm() < 1e-12);
    assert!((Curve::length(&edges[0].curve) - 20.0).abs() < 1e-9);
    // The plane's rectangle holds the whole polyline's control points: [0, 10] × [0, 10].
    assert_eq!(f.surface.domain_u(), (0.0, 10.0));
    // same_sense .F.: the edge runs from its start vertex against the curve, so the vertices
    // swap ends of the same piece and the loop runs backwards along it.
    let m = step::read(&interior_vertices_file(".F.", "#21", "#20")).unwrap();
    let BoundKind::Edges(edges) = &m.faces[0].bounds[0].kind else {
        panic!("an edge loop")
    };
    assert!((edges[0].curve.domain().0 - 0.5).abs() < 1e-12);
    assert!((edges[0].curve.domain().1 - 2.5).abs() < 1e-12);
    assert!(!edges[0].forward);
    assert!((edges[0].start() - Vec3::new(5.0, 10.0, 0.0)).norm() < 1e-12);
    // Vertices in the wrong order for the curve's direction do not bound a piece.
    let e = step::read(&interior_vertices_file(".T.", "#21", "#20")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "#10 EDGE_CURVE (line 15): its vertices do not bound a piece of its curve in the curve's direction"
    );
}

#[test]
fn unsupported_faces_can_be_skipped() {
    // Two faces in one shell, the second on a cylinder.
    let text = plane_file(MM, ".T.")
        .replace("#2 = OPEN_SHELL('',(#3));", "#2 = OPEN_SHELL('',(#3,#60));")
        .replace(
            "#40 = LINE('',#32,#41);",
            "#40 = LINE('',#32,#41);\n#60 = ADVANCED_FACE('',(),#61,.T.);\n#61 = OFFSET_SURFACE('',#40,2.,.F.);",
        );
    let strict = step::read(&text).unwrap_err();
    assert_eq!(
        strict.to_string(),
        "#61 OFFSET_SURFACE (line 36): unsupported entity, met as the surface of #60 ADVANCED_FACE (line 35)"
    );
    let lenient = step::ReadOptions {
        skip_unsupported_faces: true,
    };
    let m = step::read_with(&text, &lenient).unwrap();
    assert_eq!(m.faces.len(), 1);
    assert_eq!(m.faces[0].id, 3);
    assert_eq!(m.skipped, vec![strict]);
    // The same through a file.
    let dir = std::env::temp_dir().join(format!("tezgah-step-skip-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("two_faces.stp");
    std::fs::write(&path, &text).unwrap();
    assert_eq!(step::read_file_with(&path, &lenient).unwrap(), m);
    assert!(step::read_file(&path).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
    // A malformed file is refused all the same.
    let dangling = text.replace("#61 = OFFSET_SURFACE('',#40,2.,.F.);", "");
    assert!(matches!(
        step::read_with(&dangling, &lenient),
        Err(StepError::Dangling { .. })
    ));
}

/// Half a cylinder (r = 10 about z, 0° to 180°, z from 0 to 20) bounded by two arcs and two
/// lines with their pcurves, angles in the unit `angle_unit`, in which a half turn is `half`.
fn half_cylinder_file(angle_unit: &str, half: &str) -> String {
    file(&format!(
        "#1 = SHELL_BASED_SURFACE_MODEL('',(#2));
#2 = OPEN_SHELL('',(#3));
#3 = ADVANCED_FACE('',(#4),#10,.T.);
#4 = FACE_OUTER_BOUND('',#5,.T.);
#5 = EDGE_LOOP('',(#6,#7,#8,#9));
#6 = ORIENTED_EDGE('',*,*,#20,.T.);
#7 = ORIENTED_EDGE('',*,*,#21,.T.);
#8 = ORIENTED_EDGE('',*,*,#22,.F.);
#9 = ORIENTED_EDGE('',*,*,#23,.F.);
#10 = CYLINDRICAL_SURFACE('',#11,10.);
#11 = AXIS2_PLACEMENT_3D('',#12,#13,#14);
#12 = CARTESIAN_POINT('',(0.,0.,0.));
#13 = DIRECTION('',(0.,0.,1.));
#14 = DIRECTION('',(1.,0.,0.));
#15 = AXIS2_PLACEMENT_3D('',#16,#13,#14);
#16 = CARTESIAN_POINT('',(0.,0.,20.));
#20 = EDGE_CURVE('',#30,#31,#40,.T.);
#21 = EDGE_CURVE('',#31,#32,#41,.T.);
#22 = EDGE_CURVE('',#33,#32,#42,.T.);
#23 = EDGE_CURVE('',#30,#33,#43,.T.);
#30 = VERTEX_POINT('',#34);
#31 = VERTEX_POINT('',#35);
#32 = VERTEX_POINT('',#36);
#33 = VERTEX_POINT('',#37);
#34 = CARTESIAN_POINT('',(10.,0.,0.));
#35 = CARTESIAN_POINT('',(-10.,0.,0.));
#36 = CARTESIAN_POINT('',(-10.,0.,20.));
#37 = CARTESIAN_POINT('',(10.,0.,20.));
#40 = SURFACE_CURVE('',#44,(#50),.PCURVE_S1.);
#41 = SURFACE_CURVE('',#45,(#51),.PCURVE_S1.);
#42 = SURFACE_CURVE('',#46,(#52),.PCURVE_S1.);
#43 = SURFACE_CURVE('',#47,(#53),.PCURVE_S1.);
#44 = CIRCLE('',#11,10.);
#45 = LINE('',#35,#48);
#46 = CIRCLE('',#15,10.);
#47 = LINE('',#34,#48);
#48 = VECTOR('',#13,1.);
#50 = PCURVE('',#10,#54);
#51 = PCURVE('',#10,#55);
#52 = PCURVE('',#10,#56);
#53 = PCURVE('',#10,#57);
#54 = DEFINITIONAL_REPRESENTATION('',(#60),#70);
#55 = DEFINITIONAL_REPRESENTATION('',(#61),#70);
#56 = DEFINITIONAL_REPRESENTATION('',(#62),#70);
#57 = DEFINITIONAL_REPRESENTATION('',(#63),#70);
#60 = LINE('',#64,#68);
#61 = LINE('',#65,#69);
#62 = LINE('',#66,#68);
#63 = LINE('',#67,#69);
#64 = CARTESIAN_POINT('',(0.,0.));
#65 = CARTESIAN_POINT('',({half},0.));
#66 = CARTESIAN_POINT('',(0.,20.));
#67 = CARTESIAN_POINT('',(0.,0.));
#68 = VECTOR('',#71,1.);
#69 = VECTOR('',#72,1.);
#70 = ( GEOMETRIC_REPRESENTATION_CONTEXT(2) PARAMETRIC_REPRESENTATION_CONTEXT()
  REPRESENTATION_CONTEXT('2D SPACE',''));
#71 = DIRECTION('',(1.,0.));
#72 = DIRECTION('',(0.,1.));
#80 = ( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNIT_ASSIGNED_CONTEXT((#81,#82))
  REPRESENTATION_CONTEXT('',''));
#81 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );
#82 = {angle_unit};
#83 = PLANE_ANGLE_MEASURE_WITH_UNIT(PLANE_ANGLE_MEASURE(0.0174532925199433),#84);
#84 = ( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) );
#85 = DIMENSIONAL_EXPONENTS(0.,0.,0.,0.,0.,0.,0.);"
    ))
}

#[test]
fn half_cylinder_in_radians_and_degrees() {
    let radian = "( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) )";
    let degree = "( CONVERSION_BASED_UNIT('DEGREE',#83) NAMED_UNIT(#85) PLANE_ANGLE_UNIT() )";
    let a = step::read(&half_cylinder_file(radian, "3.141592653589793")).unwrap();
    let b = step::read(&half_cylinder_file(degree, "180.")).unwrap();
    for m in [&a, &b] {
        let f = &m.faces[0];
        let s = &f.surface;
        let (u0, u1) = s.domain_u();
        let (v0, v1) = s.domain_v();
        // u runs counter-clockwise from +x through +y to −x, v up the axis.
        assert!((s.point(u0, v0) - Vec3::new(10.0, 0.0, 0.0)).norm() < 1e-12);
        assert!((s.point(u1, v1) - Vec3::new(-10.0, 0.0, 20.0)).norm() < 1e-12);
        assert!((s.point(0.5 * (u0 + u1), v0) - Vec3::new(0.0, 10.0, 0.0)).norm() < 1e-12);
        for k in 0..=10 {
            let p = s.point(u0 + (u1 - u0) * k as f64 / 10.0, 0.5 * (v0 + v1));
            assert!(
                (p.x.hypot(p.y) - 10.0).abs() < 1e-12
                    && p.y >= -1e-12
                    && (p.z - 10.0).abs() < 1e-12
            );
        }
        let n = s.derivs(0.5 * (u0 + u1), v0);
        assert!(
            n.su.cross(&n.sv).y > 0.0,
            "the normal points out of the axis"
        );
        assert!(f.is_untrimmed(1e-9));
    }
    let (fa, fb) = (&a.faces[0].surface, &b.faces[0].surface);
    let (u0, u1) = fa.domain_u();
    assert_eq!(fb.domain_u(), (u0, u1));
    for k in 0..=10 {
        let u = u0 + (u1 - u0) * k as f64 / 10.0;
        assert!((fa.point(u, 7.0) - fb.point(u, 7.0)).norm() < 1e-12);
    }
}

/// The same surface or curve with knots written out and with knots implied by its subtype.
#[test]
fn implied_knots_equal_the_explicit_ones() {
    let pts = "#10 = CARTESIAN_POINT('',(0.,0.,0.));
#11 = CARTESIAN_POINT('',(0.,10.,1.));
#12 = CARTESIAN_POINT('',(10.,0.,2.));
#13 = CARTESIAN_POINT('',(10.,10.,3.));
#14 = CARTESIAN_POINT('',(20.,0.,5.));
#15 = CARTESIAN_POINT('',(20.,10.,4.));
#16 = CARTESIAN_POINT('',(30.,0.,1.));
#17 = CARTESIAN_POINT('',(30.,10.,0.));";
    let head = "B_SPLINE_SURFACE_WITH_KNOTS";
    let grid = "((#10,#11),(#12,#13),(#14,#15),(#16,#17)),.UNSPECIFIED.,.F.,.F.,.F.";
    let surface = |entity: &str, degree_u: usize, tail: &str| {
        let text = file(&format!(
            "#1 = {entity}('',{degree_u},1,{grid}{tail});\n{pts}"
        ));
        StepFile::parse(text.as_bytes())
            .unwrap()
            .surface(1)
            .unwrap()
    };
    // Quasi-uniform, degree 2 in u over 4 points: 0 0 0 1 2 2 2; v: 0 0 1 1.
    assert_eq!(
        surface("QUASI_UNIFORM_SURFACE", 2, ""),
        surface(head, 2, ",(3,1,3),(2,2),(0.,1.,2.),(0.,1.),.UNSPECIFIED.")
    );
    // Bézier, degree 3 in u: one piece, 0 0 0 0 1 1 1 1.
    assert_eq!(
        surface("BEZIER_SURFACE", 3, ""),
        surface(head, 3, ",(4,4),(2,2),(0.,1.),(0.,1.),.UNSPECIFIED.")
    );
    // Uniform, degree 2 in u: −2 … 4; v (degree 1, 2 points): −1 0 1 2.
    assert_eq!(
        surface("UNIFORM_SURFACE", 2, ""),
        surface(
            head,
            2,
            ",(1,1,1,1,1,1,1),(1,1,1,1),(-2.,-1.,0.,1.,2.,3.,4.),(-1.,0.,1.,2.),.UNSPECIFIED."
        )
    );
    // A Bézier curve of degree 3 over 7 points: two pieces, 0⁴ 1³ 2⁴.
    let curve = |entity: &str, tail: &str| {
        let text = file(&format!(
            "#1 = {entity}('',3,(#10,#11,#12,#13,#14,#15,#16),.UNSPECIFIED.,.F.,.F.{tail});\n{pts}"
        ));
        StepFile::parse(text.as_bytes()).unwrap().curve(1).unwrap()
    };
    assert_eq!(
        curve("BEZIER_CURVE", ""),
        curve(
            "B_SPLINE_CURVE_WITH_KNOTS",
            ",(4,3,4),(0.,1.,2.),.UNSPECIFIED."
        )
    );
    // Six points do not make Bézier pieces of degree 3.
    let text = file(&format!(
        "#1 = BEZIER_CURVE('',3,(#10,#11,#12,#13,#14,#15),.UNSPECIFIED.,.F.,.F.);\n{pts}"
    ));
    assert_eq!(
        StepFile::parse(text.as_bytes()).unwrap().curve(1).unwrap_err().to_string(),
        "#1 BEZIER_CURVE (line 8): a Bézier direction of degree 3 needs degree·k + 1 control points, not 6"
    );
}

#[test]
fn attribute_errors_name_the_attribute() {
    let two_d = file(SURFACE).replace(
        "#12 = CARTESIAN_POINT('',(10.,0.,0.));",
        "#12 = CARTESIAN_POINT('',(10.,0.));",
    );
    assert_eq!(
        step::read(&two_d).unwrap_err().to_string(),
        "#12 CARTESIAN_POINT (line 15): has 2 coordinates, a 3-D point needs 3"
    );
    let text_degree = file(SURFACE).replace(
        "B_SPLINE_SURFACE_WITH_KNOTS('',1,1,",
        "B_SPLINE_SURFACE_WITH_KNOTS('',1,'one',",
    );
    assert_eq!(
        step::read(&text_degree).unwrap_err().to_string(),
        "#4 B_SPLINE_SURFACE_WITH_KNOTS (line 11): v_degree (attribute 3) must be an integer"
    );
    let unknown_sense = file(SURFACE).replace(
        "#3 = ADVANCED_FACE('',(),#4,.T.);",
        "#3 = ADVANCED_FACE('',(),#4,.U.);",
    );
    assert_eq!(
        step::read(&unknown_sense).unwrap_err().to_string(),
        "#3 ADVANCED_FACE (line 10): same_sense (attribute 4) must be .T. or .F."
    );
    let not_a_point = file(SURFACE).replace("((#10,#11),(#12,#13))", "((#10,#11),(#12,#3))");
    assert_eq!(
        step::read(&not_a_point).unwrap_err().to_string(),
        "#3 ADVANCED_FACE (line 10): unsupported entity, met as a point of #4 B_SPLINE_SURFACE_WITH_KNOTS (line 11)"
    );
    let rational = file(&SURFACE.replace(
        "#4 = B_SPLINE_SURFACE_WITH_KNOTS('',1,1,((#10,#11),(#12,#13)),.UNSPECIFIED.,.F.,.F.,.F.,\n  (2,2),(2,2),(0.,1.),(0.,2.),.UNSPECIFIED.);",
        "#4 = ( BOUNDED_SURFACE() B_SPLINE_SURFACE(1,1,((#10,#11),(#12,#13)),.UNSPECIFIED.,.F.,.F.,.F.)
  B_SPLINE_SURFACE_WITH_KNOTS((2,2),(2,2),(0.,1.),(0.,2.),.UNSPECIFIED.) GEOMETRIC_REPRESENTATION_ITEM()
  RATIONAL_B_SPLINE_SURFACE(((1.,2.),(1.,0.))) REPRESENTATION_ITEM('') SURFACE() );",
    ));
    assert_eq!(
        step::read(&rational).unwrap_err().to_string(),
        "#4 BOUNDED_SURFACE+B_SPLINE_SURFACE+B_SPLINE_SURFACE_WITH_KNOTS+GEOMETRIC_REPRESENTATION_ITEM+RATIONAL_B_SPLINE_SURFACE+REPRESENTATION_ITEM+SURFACE (line 11): weight 3 is 0; weights must be finite and > 0"
    );
    // With valid weights the complex instance reads, and weights pull the surface: the
    // corner (0, 10, 0) weighs 2.
    let weighted = rational.replace("(((1.,2.),(1.,0.)))", "(((1.,2.),(1.,1.)))");
    let m = step::read(&weighted).unwrap();
    let p = m.faces[0].surface.point(0.5, 1.0);
    // Bilinear basis ¼ each: (Σ w·P)/(Σ w) = ((0,0,0) + 2(0,10,0) + (10,0,0) + (10,10,3))/5.
    assert!((p - Vec3::new(4.0, 6.0, 0.6)).norm() < 1e-12, "{p:?}");
}

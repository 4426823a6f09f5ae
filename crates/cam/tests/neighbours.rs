//! The part's other faces in the gouge checks (`Settings::neighbours`): a floor cut up to the
//! shoulder that stands on its edge, and the trim of a neighbouring face (its surface beyond
//! the trim is not the part and must not refuse anything). The wall is 20 mm high: the
//! flutes and shank beside it are checked as exactly as the cutting end (a 1 mm clearance
//! there stopped every pass at x = 46).

use nalgebra::Unit;
use tezgah_cam::gouge::rear::penetration;
use tezgah_cam::region::FaceRegion;
use tezgah_cam::{
    plan, CheckFace, Cutter, CutterShape, FeedDirection, Plan, Settings, StrategyKind, ToolAxis,
};
use tezgah_geom::{NurbsSurface, Vec3};

/// The bilinear patch through four corners: `S(0,0) = a`, `S(0,1) = b`, `S(1,0) = c`,
/// `S(1,1) = d`.
fn quad(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> NurbsSurface {
    let knots = vec![0.0, 0.0, 1.0, 1.0];
    NurbsSurface::bspline(1, 1, &[a, b, c, d], knots.clone(), knots).unwrap()
}

/// The floor `[0, 50]² × {0}` (normal +z) and the wall `x = 50`, 20 mm high, on its edge.
fn floor_and_wall() -> (NurbsSurface, NurbsSurface) {
    let floor = quad(
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, 50.0, 0.0),
        Vec3::new(50.0, 0.0, 0.0),
        Vec3::new(50.0, 50.0, 0.0),
    );
    let wall = quad(
        Vec3::new(50.0, 0.0, 0.0),
        Vec3::new(50.0, 50.0, 0.0),
        Vec3::new(50.0, 0.0, 20.0),
        Vec3::new(50.0, 50.0, 20.0),
    );
    (floor, wall)
}

/// Zig-zag along x (toward the wall) at h 0.05, the axis held along the normal: a ball's
/// lean would not clear the wall, and trying only costs time.
fn toward_the_wall() -> Settings {
    let mut settings = Settings::new(StrategyKind::ZigZag, 0.05, 0.005);
    settings.direction = FeedDirection::AlongU;
    if let ToolAxis::Surface { max_lead_deg, .. } = &mut settings.axis {
        *max_lead_deg = 0.0;
    }
    settings
}

/// The deepest any point of `face` (for `v` within `v_range`, if given) on a lattice of 400
/// steps each way lies in the cutting end at any location of the plan.
fn deepest_in(face: &NurbsSurface, cutter: &Cutter, p: &Plan, v_range: Option<(f64, f64)>) -> f64 {
    let n = 400;
    let (v0, v1) = v_range.unwrap_or((0.0, 1.0));
    let points: Vec<Vec3> = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| (i, j)))
        .map(|(i, j)| face.point(i as f64 / n as f64, v0 + (v1 - v0) * j as f64 / n as f64))
        .collect();
    let mut worst = f64::NEG_INFINITY;
    for c in p.path.passes.iter().flat_map(|q| &q.points) {
        let axis = Unit::new_normalize(c.axis);
        for q in points.iter().filter(|q| (*q - c.tip).norm() < 10.0) {
            worst = worst.max(penetration(&cutter.shape, &c.tip, &axis, q));
        }
    }
    worst
}

#[test]
fn a_floor_is_cut_up_to_the_wall_on_its_edge_and_no_further() {
    // Ball D6 along x toward the wall at x = 50, the axis along the floor's normal: at the
    // floor's edge the ball would stand 3 mm into the wall. With the wall as a neighbour the
    // passes end where the ball touches it (contact x = 47, found by bisection) and the
    // contacts beyond are refused as interference with the wall.
    let (floor, wall) = floor_and_wall();
    let cutter = Cutter::standard(CutterShape::Ball { radius: 3.0 });
    let mut settings = toward_the_wall();
    let alone = plan(&floor, &cutter, &settings).unwrap();
    assert!(alone.refused.is_empty());
    assert!(deepest_in(&wall, &cutter, &alone, None) > 2.9);

    settings.neighbours = vec![CheckFace {
        surface: wall.clone(),
        region: None,
    }];
    let p = plan(&floor, &cutter, &settings).unwrap();
    let deepest = deepest_in(&wall, &cutter, &p, None);
    assert!(deepest <= settings.gouge.depth_tolerance, "{deepest}");
    assert!(!p.refused.is_empty());
    assert!(p
        .refused
        .iter()
        .all(|r| r.refusal.is_interference() && r.contact.x > 47.0 - 1e-3));
    // Every pass (one per side step) ends at the wall's touch: contact x = 47.
    let ends: Vec<f64> = p
        .path
        .passes
        .iter()
        .map(|q| q.points.iter().map(|c| c.contact.x).fold(0.0, f64::max))
        .collect();
    assert_eq!(p.path.passes.len(), alone.path.passes.len());
    for x in &ends {
        assert!((x - 47.0).abs() < 3e-3, "{ends:?}");
    }
}

#[test]
fn a_neighbour_counts_only_inside_its_trim() {
    // The same wall, trimmed to y ∈ [0, 20] (a door from y 20 to 50): the passes with the
    // ball clear of it (y ≥ 23) run to the floor's edge, the others stop where the ball
    // touches the wall or its end edge.
    let (floor, wall) = floor_and_wall();
    let cutter = Cutter::standard(CutterShape::Ball { radius: 3.0 });
    let mut settings = toward_the_wall();
    // The wall's (u, v): u up the wall (z / 20), v along it (y / 50).
    let region =
        FaceRegion::new(vec![vec![(0.0, 0.0), (1.0, 0.0), (1.0, 0.4), (0.0, 0.4)]]).unwrap();
    settings.neighbours = vec![CheckFace {
        surface: wall.clone(),
        region: Some(region),
    }];
    let p = plan(&floor, &cutter, &settings).unwrap();
    let mut stopped = 0;
    for q in &p.path.passes {
        let y = q.points[0].contact.y;
        let end = q.points.iter().map(|c| c.contact.x).fold(0.0, f64::max);
        // The ball's centre (x, y, 3) stops 3 mm from the wall, or from its end edge
        // (x = 50, y = 20) beside it.
        let want = if y <= 20.0 {
            47.0
        } else if y < 23.0 {
            50.0 - (9.0 - (y - 20.0).powi(2)).sqrt()
        } else {
            50.0
        };
        // Not short of it; past it only as far as the depth tolerance lets the ball into
        // the wall (checked below on the wall itself).
        assert!(
            end >= want - 3e-3 && end <= want + 0.01,
            "y {y}: {end}, want {want}"
        );
        stopped += usize::from(want < 50.0);
    }
    let deepest = deepest_in(&wall, &cutter, &p, Some((0.0, 0.4)));
    assert!(deepest <= settings.gouge.depth_tolerance, "{deepest}");
    assert!(stopped > 0 && stopped < p.path.passes.len());
}

#[test]
fn the_simulated_cut_measures_how_deep_the_tool_went_into_a_neighbour() {
    // The verification's view of the same two plans: the cut simulated over the wall (its
    // outside −x) measures the 3 mm the ball stood in it when the floor was planned alone,
    // and nothing beyond the depth tolerance when the wall was kept out of the tool's way.
    use tezgah_cam::verify::VerifyOptions;
    use tezgah_cam::verify::{path_poses, simulate_neighbour, Bounded, Bounding, MachinedRegion};
    let (floor, wall) = floor_and_wall();
    let cutter = Cutter::standard(CutterShape::Ball { radius: 3.0 });
    let mut settings = toward_the_wall();
    let options = VerifyOptions {
        cell_mm: 0.2,
        sweep_spacing_mm: 0.05,
        region: MachinedRegion::ContactBox,
    };
    // The wall's S_u × S_v: up (+z) × along (+y) = −x, its outside (the floor's side).
    let neighbour = Bounding {
        surface: &wall,
        outward_is_su_x_sv: true,
        face: None,
    };
    let machined = Bounded {
        by: Bounding {
            surface: &floor,
            outward_is_su_x_sv: true,
            face: None,
        },
        margin: 0.001,
    };
    let deepest = |p: &Plan| {
        let poses = path_poses(&p.path, 0.05);
        simulate_neighbour(neighbour, machined, &p.path, &poses, &options)
            .unwrap()
            .expect("the tool comes near the wall")
            .gouge_depth_mm
    };
    let alone = plan(&floor, &cutter, &settings).unwrap();
    let cut = deepest(&alone);
    assert!((cut - 3.0).abs() < 1e-6, "{cut}");
    settings.neighbours = vec![CheckFace {
        surface: wall.clone(),
        region: None,
    }];
    let kept = deepest(&plan(&floor, &cutter, &settings).unwrap());
    assert!(kept <= settings.gouge.neighbour_depth_tolerance, "{kept}");
}

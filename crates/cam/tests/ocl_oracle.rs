//! Oracle: 3-axis cutter locations against OpenCAMLib's drop-cutter on a triangulation of the
//! same surface. A gouge-free 3-axis CL is exactly where the cutter, dropped along its axis,
//! first touches the surface, so OpenCAMLib's tip height at our CL's (x, y) must equal ours
//! within the mesh's faceting error (measured here, per mesh). Needs `TEZGAH_OCL_PYTHON`, a
//! Python with `opencamlib` (`.ci/install-opencamlib`); ignored by a plain `cargo test`, failing
//! without it when run.

use std::path::{Path, PathBuf};
use std::process::Command;

use tezgah_cam::{plan, testing, Cutter, CutterShape, Settings, StrategyKind, ToolAxis};
use tezgah_geom::{NurbsSurface, Vec3};

/// Mesh lattice per direction (2·N² triangles).
const N: usize = 100;
/// Most CL points sent to the oracle per cutter.
const QUERIES: usize = 200;

fn write_f64(path: &Path, data: &[f64]) {
    let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
    std::fs::write(path, bytes).unwrap();
}

fn read_f64(path: &Path) -> Vec<f64> {
    std::fs::read(path)
        .unwrap()
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

/// Triangles of the `N × N` parameter lattice, and the mesh's faceting error: the largest
/// distance between the surface and the triangle at the centroid and edge midpoints.
fn triangulate(s: &NurbsSurface) -> (Vec<f64>, f64) {
    let uv = |i: usize, j: usize| (i as f64 / N as f64, j as f64 / N as f64);
    let p = |i: usize, j: usize| {
        let (u, v) = uv(i, j);
        s.point(u, v)
    };
    let mut tris = Vec::with_capacity(18 * N * N);
    let mut sag = 0.0f64;
    for i in 0..N {
        for j in 0..N {
            for corners in [
                [(i, j), (i + 1, j), (i + 1, j + 1)],
                [(i, j), (i + 1, j + 1), (i, j + 1)],
            ] {
                let pts: Vec<Vec3> = corners.iter().map(|&(a, b)| p(a, b)).collect();
                for q in &pts {
                    tris.extend_from_slice(&[q.x, q.y, q.z]);
                }
                let uvs: Vec<(f64, f64)> = corners.iter().map(|&(a, b)| uv(a, b)).collect();
                for w in [
                    [1.0 / 3.0; 3],
                    [0.5, 0.5, 0.0],
                    [0.0, 0.5, 0.5],
                    [0.5, 0.0, 0.5],
                ] {
                    let (u, v) = (
                        w[0] * uvs[0].0 + w[1] * uvs[1].0 + w[2] * uvs[2].0,
                        w[0] * uvs[0].1 + w[1] * uvs[1].1 + w[2] * uvs[2].1,
                    );
                    let lin = pts[0] * w[0] + pts[1] * w[1] + pts[2] * w[2];
                    sag = sag.max((s.point(u, v) - lin).norm());
                }
            }
        }
    }
    (tris, sag)
}

fn oracle_script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/oracle/ocl_drop.py")
}

#[test]
#[ignore = "needs OpenCAMLib: set TEZGAH_OCL_PYTHON (see .ci/install-opencamlib)"]
fn three_axis_cutter_locations_match_opencamlib_drop_cutter() {
    let python = std::env::var_os("TEZGAH_OCL_PYTHON")
        .expect("TEZGAH_OCL_PYTHON is not set: install OpenCAMLib with .ci/install-opencamlib");
    let s = testing::freeform(0.0);
    let (tris, sag) = triangulate(&s);
    let dir = std::env::temp_dir().join(format!("tezgah-ocl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let tri_path = dir.join("mesh.f64");
    write_f64(&tri_path, &tris);
    // Vertical gap between mesh and surface ≤ sag / cos(slope); the freeform's slopes stay
    // below 60°, hence the factor 2.
    let allowed = 2.0 * sag + 1e-6;
    for (shape, kind) in [
        (CutterShape::Ball { radius: 3.0 }, "ball".to_string()),
        (CutterShape::Flat { radius: 3.0 }, "flat".to_string()),
        (
            CutterShape::BullNose {
                radius: 3.0,
                corner_radius: 1.0,
            },
            "bull:1".to_string(),
        ),
    ] {
        let mut settings = Settings::new(StrategyKind::ZigZag, 0.1, 0.01);
        settings.axis = ToolAxis::Fixed(Vec3::z());
        let p = plan(&s, &Cutter::standard(shape), &settings).unwrap();
        let cls: Vec<_> = p.path.passes.iter().flat_map(|p| &p.points).collect();
        assert!(cls.len() > 100, "{kind}: {} points", cls.len());
        let stride = cls.len().div_ceil(QUERIES);
        let picked: Vec<_> = cls.iter().step_by(stride).collect();
        let xy: Vec<f64> = picked.iter().flat_map(|c| [c.tip.x, c.tip.y]).collect();
        let (xy_path, out_path) = (dir.join("xy.f64"), dir.join("z.f64"));
        write_f64(&xy_path, &xy);
        let status = Command::new(&python)
            .arg(oracle_script())
            .arg(&tri_path)
            .arg(&kind)
            .arg(format!("{}", 2.0 * shape.radius()))
            .arg(&xy_path)
            .arg(&out_path)
            .status()
            .unwrap();
        assert!(status.success(), "oracle failed: {status}");
        let z = read_f64(&out_path);
        assert_eq!(z.len(), picked.len());
        let worst = picked
            .iter()
            .zip(&z)
            .map(|(c, z)| (c.tip.z - z).abs())
            .fold(0.0f64, f64::max);
        println!(
            "{kind}: {} CL points ({} refused), max |z − OpenCAMLib| = {worst:.2e} mm, faceting {sag:.2e} mm",
            picked.len(),
            p.refused.len()
        );
        assert!(worst <= allowed, "{kind}: {worst} > {allowed}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

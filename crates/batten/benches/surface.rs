//! Surfaces: fairing the bundled dented hood (12 × 12 bicubic control points, both methods,
//! the two outer rings held, the default tolerance and move budgets, run to their own stop),
//! and the analysis and the pictures of a 30 × 30 bicubic patch (`analyze-surface`, and
//! the mesh, camera and one 480 × 360 panel of each kind of `plot-surface`).
//!
//! The targets: 12 × 12 faired in ≤ 2 s; analyses and plots of 30 × 30 in ≤ 1 s.
//!
//! Run: `cargo bench -p batten --bench surface`

use std::hint::black_box;
use std::path::Path;

use batten::io::read_surface_json;
use batten::surface::{
    BSplineSurface, BoundaryFix, Camera, Field, Palette, Shading, SurfaceFairOptions, SurfaceMesh,
    SurfaceMethod, analyze_surface, fair_surface, isophote_range, render, zebra_range,
};
use criterion::{Criterion, criterion_group, criterion_main};

/// A 30 × 30 bicubic net over [0, 4] × [0, 2]: the hood's crown with a small waviness.
fn patch30() -> BSplineSurface {
    let n = 30;
    let control = (0..n * n)
        .map(|k| {
            let (i, j) = (k / n, k % n);
            let x = 4.0 * i as f64 / (n - 1) as f64;
            let y = 2.0 * j as f64 / (n - 1) as f64;
            let z =
                0.35 * (1.0 - ((x - 2.0) / 2.6).powi(2)) * (1.0 - 0.5 * ((y - 1.0) / 1.4).powi(2))
                    + 0.01 * (3.0 * x).sin() * (4.0 * y).sin();
            [x, y, z]
        })
        .collect();
    BSplineSurface::clamped_uniform((3, 3), (n, n), control).expect("net")
}

fn bench(c: &mut Criterion) {
    let hood = read_surface_json(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/data/hood-dented.json"),
    )
    .expect("the bundled example");
    let mut g = c.benchmark_group("surface");
    g.sample_size(10);
    for m in SurfaceMethod::ALL {
        let o = SurfaceFairOptions::default()
            .with_method(m)
            .with_fix_boundary(BoundaryFix::Tangent);
        g.bench_function(format!("fair_hood_12x12/{}", m.name()), |b| {
            b.iter(|| fair_surface(black_box(&hood), &o).expect("fair"));
        });
    }
    let s = patch30();
    g.bench_function("analyze_30x30", |b| {
        b.iter(|| analyze_surface(black_box(&s)));
    });
    g.bench_function("plot_30x30_every_kind", |b| {
        b.iter(|| {
            let mut mesh = SurfaceMesh::new(&s, &SurfaceMesh::grid(&s));
            let cam = Camera::fit([1.0, -2.0, 3.0], &[&mesh], 480, 360, 12).expect("camera");
            for f in [Field::Gaussian, Field::Mean, Field::Kappa1, Field::Kappa2] {
                mesh.set_field(f);
                let (lo, hi) = mesh.value_range().expect("values");
                let m = lo.abs().max(hi.abs());
                let shading = Shading::Map {
                    lo: -m,
                    hi: m,
                    palette: Palette::Diverging,
                };
                black_box(render(&mesh, &cam, &shading));
            }
            let light = [1.0, -2.0, 3.0];
            let (lo, hi) = isophote_range(&[&mesh], &cam, light);
            let iso = Shading::Isophotes {
                light,
                lo,
                hi,
                bands: 12,
            };
            black_box(render(&mesh, &cam, &iso));
            let (lo, hi) = zebra_range(&[&mesh], &cam);
            black_box(render(
                &mesh,
                &cam,
                &Shading::Zebra {
                    lo,
                    hi,
                    stripes: 12,
                },
            ));
        });
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

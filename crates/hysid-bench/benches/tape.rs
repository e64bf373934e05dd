//! Criterion benchmark of the tape: one Bouc–Wen evaluation of f with ∂f/∂x and ∂f/∂θ
//! (and of f alone), from `examples/equations/bouc_wen.toml`, against a hand-written Rust
//! transcription of hysid's built-in Bouc–Wen model (Noël & Schoukens 2016).
//!
//! Run with `cargo bench -p hysid-bench --bench tape`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use hysid_equations::EquationModel;

fn sign0(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// ẋ of the built-in model (θ = mL, cL, kL, α, βγ, βδ, ν).
fn hand_rhs(x: &[f64], u: &[f64], th: &[f64], dx: &mut [f64]) {
    let (y, v, z) = (x[0], x[1], x[2]);
    dx[0] = v;
    dx[1] = (u[0] - th[1] * v - th[2] * y - z) / th[0];
    let a = z.abs().powf(th[6]);
    dx[2] = th[3] * v - th[4] * v.abs() * sign0(z) * a - th[5] * v * a;
}

/// ẋ, ∂f/∂x, ∂f/∂θ of the built-in model.
fn hand_jacobians(
    x: &[f64],
    u: &[f64],
    th: &[f64],
    dx: &mut [f64],
    fx: &mut [f64],
    ft: &mut [f64],
) {
    hand_rhs(x, u, th, dx);
    let (y, v, z) = (x[0], x[1], x[2]);
    let nu = th[6];
    let a = z.abs().powf(nu);
    let da = if z == 0.0 {
        if nu == 1.0 {
            1.0
        } else {
            0.0
        }
    } else {
        nu * z.abs().powf(nu - 1.0)
    };
    let m = th[0];
    fx.fill(0.0);
    ft.fill(0.0);
    fx[1] = 1.0;
    fx[3] = -th[2] / m;
    fx[4] = -th[1] / m;
    fx[5] = -1.0 / m;
    fx[7] = th[3] - th[4] * sign0(v) * sign0(z) * a - th[5] * a;
    fx[8] = -th[4] * v.abs() * da - th[5] * v * da * sign0(z);
    let p = th.len();
    let acc = (u[0] - th[1] * v - th[2] * y - z) / m;
    ft[p] = -acc / m;
    ft[p + 1] = -v / m;
    ft[p + 2] = -y / m;
    let ln = if z == 0.0 { 0.0 } else { z.abs().ln() };
    ft[2 * p + 3] = v;
    ft[2 * p + 4] = -v.abs() * sign0(z) * a;
    ft[2 * p + 5] = -v * a;
    ft[2 * p + 6] = -(th[4] * v.abs() * sign0(z) + th[5] * v) * a * ln;
}

fn bench(c: &mut Criterion) {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/equations/bouc_wen.toml"
    ))
    .expect("examples/equations/bouc_wen.toml");
    let model = EquationModel::parse(&text).expect("bouc_wen.toml parses");
    let th = model.parameter_values();
    let (x, u) = ([1.2e-4, -3.1e-3, 4.7], [12.5]);
    let (mut dx, mut fx, mut ft) = ([0.0; 3], [0.0; 9], [0.0; 21]);
    let mut scratch = model.scratch();
    eprintln!(
        "tape lengths (f, f+J, f+Ju, h, h+J, h+Ju): {:?}",
        model.tape_lengths()
    );

    let mut g = c.benchmark_group("bouc_wen");
    g.bench_function("jacobians/tape_scratch", |b| {
        b.iter(|| {
            model.rhs_jacobians_with(
                &mut scratch,
                0.0,
                black_box(&x),
                black_box(&u),
                black_box(&th),
                &mut dx,
                &mut fx,
                &mut ft,
            );
            black_box(&ft);
        })
    });
    g.bench_function("jacobians/tape_thread_local", |b| {
        b.iter(|| {
            model.rhs_jacobians(
                0.0,
                black_box(&x),
                black_box(&u),
                black_box(&th),
                &mut dx,
                &mut fx,
                &mut ft,
            );
            black_box(&ft);
        })
    });
    g.bench_function("jacobians/hand_written", |b| {
        b.iter(|| {
            hand_jacobians(
                black_box(&x),
                black_box(&u),
                black_box(&th),
                &mut dx,
                &mut fx,
                &mut ft,
            );
            black_box(&ft);
        })
    });
    g.bench_function("rhs/tape_scratch", |b| {
        b.iter(|| {
            model.rhs_with(
                &mut scratch,
                0.0,
                black_box(&x),
                black_box(&u),
                black_box(&th),
                &mut dx,
            );
            black_box(&dx);
        })
    });
    g.bench_function("rhs/hand_written", |b| {
        b.iter(|| {
            hand_rhs(black_box(&x), black_box(&u), black_box(&th), &mut dx);
            black_box(&dx);
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! Evaluation does not allocate in steady state: a counting allocator watches this thread
//! while f, h and their Jacobians are evaluated many times, with a caller-owned scratch
//! and with the per-thread one.

use crate::common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use hysid_equations::EquationModel;

struct Counting;

thread_local! {
    static WATCHING: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: forwards every call to the system allocator unchanged; it only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if WATCHING.with(Cell::get) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if WATCHING.with(Cell::get) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Allocations on this thread while `f` runs.
fn allocations(f: impl FnOnce()) -> usize {
    COUNT.with(|c| c.set(0));
    WATCHING.with(|w| w.set(true));
    f();
    WATCHING.with(|w| w.set(false));
    COUNT.with(Cell::get)
}

#[test]
fn steady_state_evaluation_does_not_allocate() {
    for name in ["bouc_wen.toml", "cascaded_tanks.toml"] {
        let m = EquationModel::parse(&common::example(name)).unwrap();
        let (n, p, ny, mi) = (
            m.states().len(),
            m.parameters().len(),
            m.outputs().len(),
            m.inputs().len(),
        );
        let th = m.parameter_values();
        let x: Vec<f64> = (0..n).map(|i| 0.5 + i as f64).collect();
        let u = vec![1.0; mi];
        let (mut dx, mut fx, mut ft) = (vec![0.0; n], vec![0.0; n * n], vec![0.0; n * p]);
        let (mut y, mut hx, mut ht) = (vec![0.0; ny], vec![0.0; ny * n], vec![0.0; ny * p]);
        let mut scratch = m.scratch();
        // Warm-up: the per-thread scratch grows once.
        m.rhs_jacobians(0.0, &x, &u, &th, &mut dx, &mut fx, &mut ft);
        let count = allocations(|| {
            for k in 0..10_000 {
                let t = k as f64 * 1e-3;
                m.rhs(t, &x, &u, &th, &mut dx);
                m.rhs_jacobians(t, &x, &u, &th, &mut dx, &mut fx, &mut ft);
                m.output_jacobians(&x, &u, &th, &mut y, &mut hx, &mut ht);
                m.rhs_jacobians_with(&mut scratch, t, &x, &u, &th, &mut dx, &mut fx, &mut ft);
                m.output_with(&mut scratch, &x, &u, &th, &mut y);
            }
        });
        assert_eq!(count, 0, "{name}: allocations during evaluation");
        // The watch itself works.
        assert_eq!(allocations(|| drop(vec![1u8; 16])), 1);
    }
}

//! Tests of `hysid::numerics::progress`.

use hysid::numerics::progress::*;
use hysid::numerics::Control;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

#[test]
fn an_observer_sees_every_step_and_can_stop() {
    let seen = Arc::new(AtomicUsize::new(0));
    let counter = seen.clone();
    let observer = Observer::new(move |p| {
        counter.fetch_add(p.done, Ordering::SeqCst);
        if p.done >= 3 {
            Control::Stop
        } else {
            Control::Continue
        }
    });
    assert_eq!(observer.report("start", 1, 4), Control::Continue);
    assert_eq!(observer.report("start", 2, 4), Control::Continue);
    assert_eq!(observer.report("start", 3, 4), Control::Stop);
    assert_eq!(seen.load(Ordering::SeqCst), 6);
    assert_eq!(Observer::none().report("start", 3, 4), Control::Continue);
    assert!(!Observer::none().should_stop("start"));
}

//! Interrupting a running computation from outside it, such as a Ctrl-C seen by a host
//! language: [`interruptible`] runs a computation with a check that the solvers call between
//! their inner iterations (interior-point, Krylov and form-finding steps), at most every
//! [`CHECK_INTERVAL`]; when the check asks to stop, the computation is abandoned at once and
//! `interruptible` returns `None`.
//!
//! The check belongs to the calling thread: work the solvers hand to other threads does not
//! call it, and a computation on another thread is not interrupted.

use std::cell::RefCell;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::time::{Duration, Instant};

/// The least time between two calls of the check.
pub const CHECK_INTERVAL: Duration = Duration::from_millis(50);

type Check = Box<dyn FnMut() -> bool>;

thread_local! {
    static CHECK: RefCell<Option<(Check, Instant)>> = const { RefCell::new(None) };
}

/// The unwinding payload of an abandoned computation.
struct Stopped;

/// Runs `work`, calling `check` from within it (on this thread, at most every
/// [`CHECK_INTERVAL`], first after one interval); `None` when `check` returned true, which
/// abandons `work` where it was. Nested calls use the innermost check.
///
/// ```
/// let mut calls = 0;
/// let done = voussoir::interrupt::interruptible(move || { calls += 1; true }, || 42);
/// assert_eq!(done, Some(42)); // too quick to be checked
/// ```
pub fn interruptible<R>(
    check: impl FnMut() -> bool + 'static,
    work: impl FnOnce() -> R,
) -> Option<R> {
    let outer = CHECK.with(|c| c.replace(Some((Box::new(check), Instant::now()))));
    let done = catch_unwind(AssertUnwindSafe(work));
    CHECK.with(|c| *c.borrow_mut() = outer);
    match done {
        Ok(r) => Some(r),
        Err(payload) if payload.is::<Stopped>() => None,
        Err(payload) => resume_unwind(payload),
    }
}

/// Calls this thread's check if one is installed and its interval has passed; abandons the
/// computation (unwinding to [`interruptible`]) if it asks to stop.
pub(crate) fn poll() {
    let due = CHECK.with(|c| {
        let mut c = c.borrow_mut();
        match c.as_mut() {
            Some((_, last)) if last.elapsed() >= CHECK_INTERVAL => c.take(),
            _ => None,
        }
    });
    let Some((mut check, _)) = due else { return };
    let stop = check();
    CHECK.with(|c| *c.borrow_mut() = Some((check, Instant::now())));
    if stop {
        // Not a panic: no panic hook runs, nothing is printed.
        resume_unwind(Box::new(Stopped));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_check_that_asks_to_stop_abandons_the_work() {
        let steps = std::cell::Cell::new(0);
        let done = interruptible(
            || true,
            || loop {
                steps.set(steps.get() + 1);
                poll();
            },
        );
        assert_eq!(done, None::<()>);
        assert!(steps.get() > 1);
        // Uninstalled again: a poll outside does nothing.
        poll();
    }

    #[test]
    fn a_check_that_lets_go_on_is_called_at_intervals() {
        let calls = std::rc::Rc::new(std::cell::Cell::new(0));
        let seen = calls.clone();
        let done = interruptible(
            move || {
                seen.set(seen.get() + 1);
                false
            },
            || {
                let start = Instant::now();
                while start.elapsed() < 3 * CHECK_INTERVAL + CHECK_INTERVAL / 2 {
                    poll();
                }
                7
            },
        );
        assert_eq!(done, Some(7));
        assert!((2..=3).contains(&calls.get()), "{}", calls.get());
    }

    #[test]
    fn other_panics_pass_through() {
        let r = catch_unwind(|| interruptible(|| false, || panic!("boom")));
        assert!(r.is_err());
    }
}

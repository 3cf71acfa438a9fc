//! Ctrl-C during a long call. Python runs its signal handlers only on the main thread and only
//! when that thread runs Python code; a call that releases the GIL for seconds of Rust work
//! would otherwise ignore Ctrl-C until it ends. [`interruptible`] runs the work on a worker
//! thread and keeps the calling thread checking Python's signals every 20 ms: a handler that
//! raises (the default SIGINT handler raises `KeyboardInterrupt`) sets the stop flag the work
//! was given, the work stops at its next step and returns what it computed, and the exception
//! is handed back with it.

use pdyn_ode::Interrupt;
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

/// How often the calling thread looks for a signal.
const POLL: Duration = Duration::from_millis(20);

/// What [`interruptible`] gives back: the work's result, and whether Ctrl-C stopped it.
pub(crate) struct Finished<T> {
    /// The work's result (partial when interrupted).
    pub value: T,
    /// Ctrl-C (`KeyboardInterrupt`) arrived while the work ran; it was told to stop.
    pub interrupted: bool,
}

/// Runs `work` with the GIL released on a worker thread, handing it a stop flag that Ctrl-C
/// sets. An exception other than `KeyboardInterrupt` raised by a signal handler (a custom
/// SIGINT handler, `SystemExit`) also stops the work and is returned as the error; a panic in
/// the work unwinds into the caller (`errors::guarded` turns it into `PdynError`).
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(Interrupt) -> T + Send,
) -> PyResult<Finished<T>> {
    let flag: Interrupt = Arc::new(AtomicBool::new(false));
    let worker_flag = flag.clone();
    with_flag(py, flag, move || work(worker_flag))
}

/// [`interruptible`] with the stop flag made by the caller (who has already handed it to the
/// work, e.g. in solver options).
pub(crate) fn with_flag<T: Send>(
    py: Python<'_>,
    flag: Interrupt,
    work: impl FnOnce() -> T + Send,
) -> PyResult<Finished<T>> {
    // The worker says it is done through this (also when it panics: the guard's drop), so a
    // short call returns at once rather than at the next poll.
    let done = (Mutex::new(false), Condvar::new());
    std::thread::scope(|scope| {
        let done = &done;
        let worker = scope.spawn(move || {
            let _tell = Done(done);
            work()
        });
        let mut raised: Option<PyErr> = None;
        loop {
            let finished = py.allow_threads(|| {
                let guard = done.0.lock().unwrap_or_else(|e| e.into_inner());
                let (guard, _) = done
                    .1
                    .wait_timeout_while(guard, POLL, |finished| !*finished)
                    .unwrap_or_else(|e| e.into_inner());
                *guard
            });
            if finished {
                break;
            }
            if raised.is_none() {
                if let Err(e) = py.check_signals() {
                    flag.store(true, Ordering::Relaxed);
                    raised = Some(e);
                }
            }
        }
        let value = match worker.join() {
            Ok(v) => v,
            Err(panic) => std::panic::resume_unwind(panic),
        };
        match raised {
            Some(e) if !e.is_instance_of::<PyKeyboardInterrupt>(py) => Err(e),
            Some(_) => Ok(Finished {
                value,
                interrupted: true,
            }),
            None => Ok(Finished {
                value,
                interrupted: false,
            }),
        }
    })
}

/// Marks the work done when dropped: at its end, or while a panic unwinds out of it.
struct Done<'a>(&'a (Mutex<bool>, Condvar));

impl Drop for Done<'_> {
    fn drop(&mut self) {
        *self.0 .0.lock().unwrap_or_else(|e| e.into_inner()) = true;
        self.0 .1.notify_all();
    }
}

/// Ctrl-C for work that runs on the calling thread itself with the GIL released (a compiled
/// `solve_ivp`, most of which last well under a millisecond: a worker thread per call cost
/// ~50 µs, more than the solve). The work calls [`SignalWatch::tick`] often (every evaluation
/// of its right-hand side); every `stride` ticks the watch reads the clock, and once [`POLL`]
/// has passed it takes the GIL and runs Python's signal handlers. A handler that raises sets
/// the stop flag (the solver stops at its next step) and the exception is kept. The stride
/// adapts so that the clock is read about every millisecond whatever one tick costs.
pub(crate) struct SignalWatch {
    flag: Interrupt,
    ticks: std::cell::Cell<u32>,
    stride: std::cell::Cell<u32>,
    last_clock: std::cell::Cell<std::time::Instant>,
    last_poll: std::cell::Cell<std::time::Instant>,
    raised: std::cell::RefCell<Option<PyErr>>,
}

impl SignalWatch {
    /// A watch that sets `flag` when a signal handler raises.
    pub(crate) fn new(flag: Interrupt) -> Self {
        let now = std::time::Instant::now();
        SignalWatch {
            flag,
            ticks: 0.into(),
            stride: 16.into(),
            last_clock: now.into(),
            last_poll: now.into(),
            raised: None.into(),
        }
    }

    /// One unit of work done.
    #[inline]
    pub(crate) fn tick(&self) {
        let t = self.ticks.get() + 1;
        if t < self.stride.get() {
            self.ticks.set(t);
            return;
        }
        self.ticks.set(0);
        self.look();
    }

    #[cold]
    fn look(&self) {
        let now = std::time::Instant::now();
        let since = now.duration_since(self.last_clock.get());
        self.last_clock.set(now);
        let stride = self.stride.get();
        if since < Duration::from_micros(500) && stride < 1 << 20 {
            self.stride.set(stride * 2);
        } else if since > Duration::from_millis(4) && stride > 1 {
            self.stride.set(stride / 2);
        }
        if now.duration_since(self.last_poll.get()) < POLL || self.raised.borrow().is_some() {
            return;
        }
        self.last_poll.set(now);
        if let Err(e) = Python::with_gil(|py| py.check_signals()) {
            self.flag.store(true, Ordering::Relaxed);
            *self.raised.borrow_mut() = Some(e);
        }
    }

    /// The exception a signal handler raised, if one did.
    pub(crate) fn into_raised(self) -> Option<PyErr> {
        self.raised.into_inner()
    }
}

//! Ctrl-C, and a caller's progress callback, during a call that runs without the GIL. Python
//! only notes a signal when it arrives and raises KeyboardInterrupt once the main thread runs
//! Python again, which a call into Rust does not: so a render asks for it every
//! [`CHECK_EVERY`], and the fit and the analyses, which cannot be asked to stop, run on a thread
//! of their own while the caller waits and asks.

use std::cell::{Cell, RefCell};
use std::sync::mpsc::{sync_channel, RecvTimeoutError};
use std::time::{Duration, Instant};

use pyo3::panic::PanicException;
use pyo3::prelude::*;
use sake_glug_render::RenderObserver;

/// How often a long call looks for Ctrl-C (and calls the progress callback): often enough for a
/// person, seldom enough that taking the GIL costs nothing measurable.
pub const CHECK_EVERY: Duration = Duration::from_millis(20);

/// A render's look at Python every [`CHECK_EVERY`]: a pending signal first (Ctrl-C raises
/// KeyboardInterrupt), then the caller's `progress(done, total)`. Whatever either raises stops the
/// render and is kept, to be raised when the call returns.
pub struct Ticks {
    last: Cell<Instant>,
    rendered: Cell<u64>,
    /// The render's length in samples, when known before it ends.
    total: Option<u64>,
    progress: Option<Py<PyAny>>,
    raised: RefCell<Option<PyErr>>,
}

impl Ticks {
    pub fn new(progress: Option<Py<PyAny>>, total: Option<u64>) -> Self {
        Self {
            last: Cell::new(Instant::now()),
            rendered: Cell::new(0),
            total,
            progress,
            raised: RefCell::new(None),
        }
    }

    /// Whether the render is to stop: asked after every block, it looks only every
    /// [`CHECK_EVERY`].
    pub fn stop(&self) -> bool {
        if self.last.get().elapsed() < CHECK_EVERY {
            return false;
        }
        self.last.set(Instant::now());
        let looked = Python::attach(|py| {
            py.check_signals()?;
            if let Some(progress) = &self.progress {
                progress.call1(py, (self.rendered.get(), self.total))?;
            }
            Ok(())
        });
        match looked {
            Ok(()) => false,
            Err(error) => {
                *self.raised.borrow_mut() = Some(error);
                true
            }
        }
    }

    /// What stopped the render, if Python raised it.
    pub fn raised(self) -> Option<PyErr> {
        self.raised.into_inner()
    }
}

impl RenderObserver for Ticks {
    fn progress(&mut self, rendered: u64) {
        self.rendered.set(rendered);
    }

    fn interrupted(&self) -> bool {
        self.stop()
    }
}

/// Runs `work` on a thread of its own and waits for it without the GIL, looking for a signal
/// every [`CHECK_EVERY`]: Ctrl-C raises KeyboardInterrupt at once. The work cannot be stopped
/// from outside (the fit and the analyses take no stop flag), so it runs on to its end, or stays
/// blocked on a FIFO that nothing writes, and its result is dropped.
pub fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce() -> T + Send + 'static,
) -> PyResult<T> {
    let (done, mut result) = sync_channel(1);
    std::thread::Builder::new()
        .name("sake_glug".into())
        .spawn(move || {
            // The caller may have stopped waiting: then nobody takes the result.
            let _ = done.send(work());
        })
        .map_err(|error| {
            pyo3::exceptions::PyRuntimeError::new_err(format!("cannot start a thread: {error}"))
        })?;
    loop {
        // The receiver goes along and back: it may be moved to another thread, not shared.
        let (receiver, received) = py.detach(move || {
            let received = result.recv_timeout(CHECK_EVERY);
            (result, received)
        });
        result = receiver;
        match received {
            Ok(value) => return Ok(value),
            Err(RecvTimeoutError::Timeout) => py.check_signals()?,
            // Its panic message is printed by Rust's hook as it unwinds.
            Err(RecvTimeoutError::Disconnected) => {
                return Err(PanicException::new_err(
                    "the work panicked: a bug in Sake Glug, please report it",
                ))
            }
        }
    }
}

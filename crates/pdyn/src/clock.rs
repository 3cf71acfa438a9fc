//! Wall-clock time for the reports (loop seconds, atom-steps per second). The standard
//! library has no clock on `wasm32-unknown-unknown` (`Instant::now` panics there), so a
//! WebAssembly front end installs one ([`set_source`]: the page's `performance.now()`);
//! without a source there, times are NaN (`null` in JSON), never a made-up number.

use std::sync::OnceLock;

/// Milliseconds from an arbitrary origin, as `performance.now()` gives them.
static SOURCE: OnceLock<fn() -> f64> = OnceLock::new();

/// Installs the clock of a platform without `std::time::Instant` (first call wins).
pub fn set_source(now_ms: fn() -> f64) {
    let _ = SOURCE.set(now_ms);
}

/// Time since [`Stopwatch::start`].
#[derive(Clone, Copy, Debug)]
pub struct Stopwatch {
    #[cfg(not(target_arch = "wasm32"))]
    start: std::time::Instant,
    #[cfg(target_arch = "wasm32")]
    start_ms: f64,
}

impl Stopwatch {
    /// Starts timing now.
    pub fn start() -> Stopwatch {
        Stopwatch {
            #[cfg(not(target_arch = "wasm32"))]
            start: std::time::Instant::now(),
            #[cfg(target_arch = "wasm32")]
            start_ms: SOURCE.get().map_or(f64::NAN, |now| now()),
        }
    }

    /// Seconds elapsed (NaN where no clock exists).
    pub fn seconds(&self) -> f64 {
        #[cfg(not(target_arch = "wasm32"))]
        {
            self.start.elapsed().as_secs_f64()
        }
        #[cfg(target_arch = "wasm32")]
        {
            SOURCE
                .get()
                .map_or(f64::NAN, |now| (now() - self.start_ms) / 1e3)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stopwatch_counts_forward() {
        let w = Stopwatch::start();
        std::thread::sleep(std::time::Duration::from_millis(5));
        let s = w.seconds();
        assert!((0.004..10.0).contains(&s), "{s}");
    }
}

//! One scoped thread per item: independent pieces of work (a file's parts, a track's
//! coordinates) run at once, results in the items' order. A thread that panics gives
//! `DataError` saying so, not a second panic.

use crate::error::DataError;

/// `f` applied to each item on its own thread (the calling thread when there is one item),
/// results in order. `what` names the work in the message of a thread that panicked.
pub(crate) fn map<I, T, F>(items: &[I], what: &str, f: F) -> Vec<Result<T, DataError>>
where
    I: Sync,
    T: Send,
    F: Fn(&I) -> Result<T, DataError> + Sync,
{
    if items.len() == 1 {
        return vec![f(&items[0])];
    }
    std::thread::scope(|s| {
        let f = &f;
        let handles: Vec<_> = items.iter().map(|item| s.spawn(move || f(item))).collect();
        handles
            .into_iter()
            .map(|h| {
                h.join().unwrap_or_else(|_| {
                    Err(DataError::new(
                        "",
                        format!("internal error: a thread of {what} panicked"),
                    ))
                })
            })
            .collect()
    })
}

//! Long runs (issue 29): the options that keep their memory bounded and let them continue
//! after a stop ([`LongRun`]).

/// How a long run writes and resumes: the command line's defaults and `--checkpoint-every`,
/// `--restart` (Python's runs keep [`LongRun::default`]: the whole history in memory).
#[derive(Clone, Debug, Default)]
pub struct LongRun {
    /// With `Request::out`: rows go only to the files as the run goes; the result keeps the
    /// first and last output (bounded memory) instead of every row. Ignored with plots.
    pub stream_only: bool,
}

//! Progress of long library calls (the cases of a suite, the rungs of a study), reported to an
//! observer the caller chooses: the command line draws a bar, a library user may log or ignore
//! it. Reporting never changes a result.

/// Receives the progress of a long call. Cases run in parallel, so the methods take `&self`
/// and may be called from several threads.
pub trait Progress: Sync {
    /// A phase of `total` items begins; `unit` names them ("cases", "rungs").
    fn begin(&self, _total: usize, _unit: &str) {}
    /// Work on `item` (a case id, a rung) starts.
    fn start(&self, _item: &str) {}
    /// One item is finished.
    fn advance(&self) {}
    /// The phase is over.
    fn finish(&self) {}
}

/// Ignores all progress.
pub struct Silent;

impl Progress for Silent {}

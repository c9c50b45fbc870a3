//! The largest accepted sizes: absurd inputs fail early with a message instead of exhausting
//! memory.

/// Largest accepted scene file.
pub const MAX_FILE_BYTES: usize = 1 << 20;
/// Largest number of links in a planar chain.
pub const MAX_LINKS: usize = 8;
/// Largest number of contacts in a planar chain.
pub const MAX_CONTACTS: usize = 8;
/// Largest number of rocket stages.
pub const MAX_STAGES: usize = 4;
/// Largest number of discrete masses on the rocket.
pub const MAX_DISCRETE_MASSES: usize = 32;
/// Largest number of field stations sampled per link.
pub const MAX_FIELD_STATIONS: usize = 1001;
/// Largest number of output samples t_end / output_interval.
pub const MAX_OUTPUT_SAMPLES: f64 = 1.0e6;

/// The number of output samples t_end / output_interval when it is above
/// [`MAX_OUTPUT_SAMPLES`] (None for an acceptable count, or for values the positivity checks
/// refuse).
pub fn excess_output_samples(t_end: f64, output_interval: f64) -> Option<f64> {
    let samples = t_end / output_interval;
    (t_end.is_finite() && output_interval > 0.0 && samples > MAX_OUTPUT_SAMPLES).then_some(samples)
}
/// Largest number of wheels of a mobile platform.
pub const MAX_WHEELS: usize = 16;

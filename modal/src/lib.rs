//! placeholder (being written)
pub mod rocket;

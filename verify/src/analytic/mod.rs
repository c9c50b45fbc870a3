//! Analytic references (being written)

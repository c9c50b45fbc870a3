pub mod analytic;

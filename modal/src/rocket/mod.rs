//! Rocket by free-free eigenfunctions (being written)

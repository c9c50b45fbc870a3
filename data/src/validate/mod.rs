//! Semantic validation: what TOML syntax and serde types cannot express.
//!
//! Each problem names the field and the form it should take. Limits on sizes are stated in
//! [`limits`] (and in the README) so that absurd inputs fail early with a message instead of
//! exhausting memory.
//!
//! * [`issue`] — one problem, and the checker's common field checks (positive, finite, …);
//! * [`limits`] — the largest accepted sizes;
//! * [`scene_file`] — the file as a whole: name, simulation, exactly one model family;
//! * one module per family for [`validate`]: `planar` (links and contacts, with `joint` shared
//!   with the payload link's base), `payload`, `rocket`, `mobile` (with `body` for rigid-body
//!   mass properties); `inertia` holds the 3×3 matrix tests (Sylvester's criteria).

mod body;
mod inertia;
pub mod issue;
mod joint;
pub mod limits;
mod mobile;
mod payload;
mod planar;
mod rocket;
pub mod scene_file;

use crate::locate::FieldPath;
use crate::scene::{Model, Scene};
use issue::{Checker, Issue};

/// All semantic problems of a scene's model, in document order as far as possible.
pub fn validate(scene: &Scene) -> Vec<Issue> {
    let mut c = Checker { issues: Vec::new() };
    match &scene.model {
        Model::PlanarChain(chain) => planar::check_planar_chain(&mut c, chain),
        Model::Rocket(r) => rocket::check_rocket(&mut c, &FieldPath::root().key("rocket"), r),
        Model::PayloadLink(p) => {
            payload::check_payload_link(&mut c, &FieldPath::root().key("payload_link"), p)
        }
        Model::MobileManipulator(m) => mobile::check_mobile(&mut c, m),
    }
    c.issues
}

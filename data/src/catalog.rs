//! The embedded scene catalog (`data/scenes/*.toml`), so the tool works with no files around.

use crate::error::LoadError;
use crate::reader::parse_scene;
use crate::scene::Scene;

macro_rules! catalog {
    ($($name:literal),* $(,)?) => {
        /// (name, TOML text) of every catalog scene, in display order.
        pub const CATALOG: &[(&str, &str)] = &[
            $(($name, include_str!(concat!("../scenes/", $name, ".toml")))),*
        ];
    };
}

catalog!(
    "cantilever",
    "cantilever-axial",
    "cantilever-tip-mass",
    "cantilever-timoshenko",
    "rotating-beam",
    "rotating-beam-axial",
    "spin-up",
    "spin-up-linear",
    "spin-up-axial",
    "single-link",
    "two-link-free",
    "two-link-free-undamped",
    "two-link-free-undamped-swing",
    "barhorst-case1",
    "barhorst-case2",
    "barhorst-case1-tipmass",
    "barhorst-case1-timoshenko",
    "barhorst-case1-stiff-elbow",
    "constrained-arm",
    "rocket",
    "rocket-case2",
    "rocket-launch-60",
    "rocket-launch-75",
    "single-link-3d",
    "single-link-3d-constant-rate",
    "single-link-3d-soft-sag",
    "single-link-3d-stiff",
    "single-link-3d-thin",
    "single-link-3d-heavy-payload",
    "mobile-manipulator",
    "mobile-platform",
    "mobile-arm-fixed-base",
    "mobile-manipulator-flexible",
);

/// Names of the catalog scenes.
pub fn catalog_names() -> impl Iterator<Item = &'static str> {
    CATALOG.iter().map(|(n, _)| *n)
}

/// Parses a catalog scene by name.
pub fn catalog_scene(name: &str) -> Option<Result<Scene, LoadError>> {
    CATALOG
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(n, text)| parse_scene(text, &format!("<catalog>/{n}.toml")).map_err(LoadError::from))
}

/// Loads a scene by catalog name or, failing that, by file path.
pub fn load_scene(name_or_path: &str) -> Result<Scene, LoadError> {
    if let Some(r) = catalog_scene(name_or_path) {
        return r;
    }
    let path = std::path::Path::new(name_or_path);
    if !path.exists() {
        return Err(LoadError::NotFound(name_or_path.to_string()));
    }
    let text = std::fs::read_to_string(path).map_err(|source| LoadError::Io {
        path: name_or_path.to_string(),
        source,
    })?;
    Ok(parse_scene(&text, name_or_path)?)
}

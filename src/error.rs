//! Errors that are the user's to fix (exit code 2), as opposed to everything else (exit code 1).

/// Bad input: a scene, a flag or a file name. The message says what and where.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct InputError(pub String);

impl From<crate::scene::SceneError> for InputError {
    fn from(e: crate::scene::SceneError) -> Self {
        InputError(e.to_string())
    }
}

//! A model file read once and told apart once: a mechanics model, an `[nbody]` model or an
//! `[md]` model. The front ends read the file through [`ModelFile::read`] and hand it to the
//! kind's engine; the commands that work on mechanics models only ([`ModelFile::mechanics`])
//! refuse the other kinds with a located error naming `pdyn run`.

use crate::Error;
use pdyn_mech::{Model, ModelError};
use std::path::Path;

/// Which engine a model file is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Particles, forces, constraints: derived equations of motion (`pdyn_mech::Model`).
    Mechanics,
    /// A top-level `[nbody]` table (`crate::nbody`).
    Nbody,
    /// A top-level `[md]` table (`crate::md`).
    Md,
}

impl Kind {
    /// The kind as `summary.json` names it (`crate::summary::KINDS`).
    pub fn name(self) -> &'static str {
        let [mechanics, nbody, md] = crate::summary::KINDS;
        match self {
            Kind::Mechanics => mechanics,
            Kind::Nbody => nbody,
            Kind::Md => md,
        }
    }
}

/// A model file's text, its name for messages, and its kind.
#[derive(Clone, Debug)]
pub struct ModelFile {
    /// The name errors show (the path as given).
    pub origin: String,
    /// The text (UTF-8; a file that is not is a located error from [`ModelFile::read`]).
    pub source: String,
    /// Which engine it is for.
    pub kind: Kind,
}

impl ModelFile {
    /// Reads the file at `path` (once) and tells its kind.
    pub fn read(path: &Path) -> Result<ModelFile, Error> {
        let source = Error::read_model_file(path)?;
        Ok(ModelFile::from_source(source, path.display().to_string()))
    }

    /// A model given as text. A text that is not TOML is a mechanics model here: the mechanics
    /// loader reports where it fails to parse.
    pub fn from_source(source: String, origin: String) -> ModelFile {
        // One parse tells the kinds apart by their top-level table.
        let kind = match source.parse::<toml::Table>() {
            Ok(t) if t.contains_key("nbody") => Kind::Nbody,
            Ok(t) if t.contains_key("md") => Kind::Md,
            _ => Kind::Mechanics,
        };
        ModelFile {
            origin,
            source,
            kind,
        }
    }

    /// The mechanics model; an `[nbody]` or `[md]` model is a located error at its table that
    /// says `pdyn run` runs it (they have no symbolic equations to derive or check).
    pub fn mechanics(&self) -> Result<Model, Error> {
        self.mechanics_with(pdyn_mech::load)
    }

    /// [`ModelFile::mechanics`] with its force families left unexpanded where they share one
    /// representative's loads ([`pdyn_mech::model::load_deferring`]): for `pdyn run`, whose
    /// preparation expands them unless the model runs as free particles.
    pub fn mechanics_deferring(&self) -> Result<Model, Error> {
        self.mechanics_with(pdyn_mech::model::load_deferring)
    }

    fn mechanics_with(
        &self,
        load: fn(&str, &str) -> Result<Model, ModelError>,
    ) -> Result<Model, Error> {
        let refusal = |error: ModelError| Error::Model {
            error,
            source: self.source.as_str().into(),
        };
        match self.kind {
            Kind::Nbody => {
                let span = crate::nbody::spec::nbody_table_span(&self.source).unwrap_or(0..0);
                Err(refusal(
                    ModelError::new(&self.origin, span, "N-body model: use `pdyn run`").help(
                        "an [nbody] table is integrated by pdyn run; it has no symbolic equations (docs/nbody.md)",
                    ),
                ))
            }
            Kind::Md => {
                let at = self.source.find("[md").unwrap_or(0);
                // four characters, ending on a character boundary
                let len: usize = self.source[at..].chars().take(4).map(char::len_utf8).sum();
                Err(refusal(
                    ModelError::new(
                        &self.origin,
                        at..at + len,
                        "molecular-dynamics model: use `pdyn run` (this command works on mechanics models)",
                    )
                    .help("an [md] model has pair potentials and thermostats, not equations of motion to derive"),
                ))
            }
            Kind::Mechanics => load(&self.source, &self.origin).map_err(refusal),
        }
    }
}

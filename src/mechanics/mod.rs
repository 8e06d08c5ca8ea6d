//! Mechanics of pushing: the support's limit surface (friction load as a function of the part's
//! twist). Later: the one-instant contact solve, integration over a contact, fences.

pub mod limit_surface;

//! Fault injection: sphrepro used as a hostile but fair user would use it. Every scene's
//! declared parameters at values no one should give (generated from the declarations, so a
//! new scene is covered as soon as it declares its parameters), malformed problem files,
//! kills and resumes, two writers on one folder, a full disk, a read-only folder and a
//! damaged result. Each case must be refused with the key or the file named, or end
//! `diverged`, or `completed` with finite metrics, within a time limit: never hang, never
//! panic, never leave a result that looks finished when it is not.
//!
//! One module per kind of fault; `common` holds what they share.

mod common;
mod damaged;
mod disk;
mod hostile;
mod memory;
mod not_finite;
mod output;
mod problem_files;
mod resume;
mod snapshots;
mod times;
mod two_writers;

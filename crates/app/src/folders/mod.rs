//! Output folders: where results go and what may be replaced there ([`output`]), the lock
//! that keeps two runs out of one folder ([`lock`]), and the file helpers every command
//! writes through ([`io`]: atomic writes, the parameter-file reader). Nothing here knows what
//! a command found.

pub mod io;
pub mod lock;
pub mod output;

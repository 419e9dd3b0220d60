//! One module per subcommand.

pub mod post;
pub mod run;
pub mod verify;

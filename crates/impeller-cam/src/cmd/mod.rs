//! One module per subcommand.

pub mod model;
pub mod post;
pub mod run;
pub mod stiffness;
pub mod verify;

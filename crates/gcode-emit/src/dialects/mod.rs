//! Built-in controller dialects.

mod common;
mod fanuc;
mod heidenhain;
mod heidenhain_conversational;
mod linuxcnc;
mod sinumerik;

pub use fanuc::Fanuc;
pub use heidenhain::HeidenhainIso;
pub use heidenhain_conversational::{HeidenhainConversational, Tcpm};
pub use linuxcnc::{KinematicsSwitch, LinuxCnc};
pub use sinumerik::Sinumerik;

//! Built-in controller dialects.

mod common;
mod fanuc;
mod heidenhain;
mod linuxcnc;
mod sinumerik;

pub use fanuc::Fanuc;
pub use heidenhain::HeidenhainIso;
pub use linuxcnc::LinuxCnc;
pub use sinumerik::Sinumerik;

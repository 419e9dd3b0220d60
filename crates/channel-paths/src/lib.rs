//! Tool paths inside an impeller channel, each an [`cam_plan::Operation`]:
//! roughing by depth levels with triangle path planning (paper 001 §3, channel areas around
//! the splitter of paper 003), hub finishing and blade-root finishing along the intersection
//! of the hub's and the blade's offset surfaces (paper 004 §2–3), and rest finishing of what
//! the earlier operations leave (paper 003 §4's secondary cut).

mod accessibility;
pub mod ball_fit;
pub mod blade_root;
pub mod hub_finishing;
pub mod rest_finishing;
pub mod root_axis;
pub mod roughing;

pub use blade_root::{build_blade_root_finishing, BladeRootFinishing, BLADE_ROOT_FINISHING};
pub use hub_finishing::{build_hub_finishing, HubFinishing, HUB_FINISHING};
pub use rest_finishing::{build_rest_finishing, RestFinishing, REST_FINISHING};
pub use roughing::{build_channel_roughing, CHANNEL_ROUGHING};

// The README's code blocks are compiled and run as doc tests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

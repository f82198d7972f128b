//! Game-agnostic learning: the actor-critic on candle ([`policy`]), [`ppo`] with its hand-written
//! forward/backward pass ([`fused`]) and optimizer ([`adam`]), running observation normalization
//! ([`normalizer`]), the rollout loop over many environments ([`vec_env`]), where its time goes
//! ([`timing`], with a clock the caller lends) and policy and checkpoint files ([`checkpoint`]).
//! Nothing here reads the clock or prints.

pub mod adam;
pub mod checkpoint;
pub mod fused;
pub mod normalizer;
pub mod policy;
pub mod ppo;
pub mod timing;
pub mod vec_env;

//! Game-agnostic learning on candle: the actor-critic [`policy`], [`ppo`] with its optimizer
//! ([`adam`]), running observation normalization ([`normalizer`]) and the rollout loop over many
//! environments ([`vec_env`]); candle's thread count ([`threads`]). Nothing here reads the clock or prints.

pub mod adam;
pub mod checkpoint;
pub mod normalizer;
pub mod policy;
pub mod ppo;
pub mod threads;
pub mod vec_env;

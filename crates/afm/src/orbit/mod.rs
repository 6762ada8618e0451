//! The periodic orbit at one separation and what is read off it (MODEL.md sections 4 and 5):
//! the steady orbit (shooting from the free orbit or the approach walk), its observables
//! (harmonics, impacts, gap minima, force integrals), the lock-in of a time-domain run, the
//! quadrature they use, the predicted start of the next orbit on a branch, and sampled
//! trajectories for figures.
pub mod gauss_legendre;
pub mod lockin;
pub mod observables;
pub mod prediction;
pub mod steady_orbit;
pub mod trajectory;

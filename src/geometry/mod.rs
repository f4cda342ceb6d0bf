//! Neighbour search shared by the engines.

//! Pictures of runs: bodies drawn as shaded ellipsoids and spheres by exact ray casting, written as PNG frames and
//! an animated GIF.

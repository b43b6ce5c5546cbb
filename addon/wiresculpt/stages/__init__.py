"""The pipeline's stages, one module each, each filling its part of the design document."""

"""Fabrication, free of bpy: export files and streaming to a bender (mirrors native/src/fab)."""

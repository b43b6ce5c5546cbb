"""Everything that reads or writes Blender data, below the operators: objects and tags, slicing
handles and contour curves, the design's results in the scene, cut handles, the assembly guide's
renders, meshes and mesh files. Imports point down only (pipeline, stages, fab, core, native)."""

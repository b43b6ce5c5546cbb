"""Pure-Python parts of wiresculpt: no bpy here, so the batch script and plain Python tests can
import them. Scene-file reading, contour picking, the design document."""

"""One way to register: a module's classes (and the scene properties pointing at its property
groups), its handlers of bpy.app.handlers, and a package's modules in order."""
import bpy


def classes_factory(classes, scene_properties=()):
    """(register, unregister) for `classes`, registered in order and unregistered in reverse;
    `scene_properties`: (attribute, PropertyGroup class, name, description) added to bpy.types.Scene
    after the classes and removed before them."""
    def register():
        for cls in classes:
            bpy.utils.register_class(cls)
        for attribute, group, name, description in scene_properties:
            setattr(bpy.types.Scene, attribute,
                    bpy.props.PointerProperty(type=group, name=name, description=description))

    def unregister():
        for attribute, *_rest in reversed(scene_properties):
            delattr(bpy.types.Scene, attribute)
        for cls in reversed(classes):
            bpy.utils.unregister_class(cls)

    return register, unregister


def handlers_factory(handlers):
    """(register, unregister) for `handlers`: (name of a bpy.app.handlers list, function) pairs,
    each function added to its list once and removed from it if there."""
    def register():
        for kind, handler in handlers:
            if handler not in getattr(bpy.app.handlers, kind):
                getattr(bpy.app.handlers, kind).append(handler)

    def unregister():
        for kind, handler in handlers:
            if handler in getattr(bpy.app.handlers, kind):
                getattr(bpy.app.handlers, kind).remove(handler)

    return register, unregister


def modules_factory(modules):
    """(register, unregister) calling each module's own, in order and in reverse."""
    def register():
        for module in modules:
            module.register()

    def unregister():
        for module in reversed(modules):
            module.unregister()

    return register, unregister

"""glint's sky as a Cycles world, for the scripts that render glint's scenes in Blender
(bpy 4.5 or Blender 3.4): an equirectangular map turned to glint's orientation and read
nearest-texel, as glint reads it, or a constant colour.

Scripts elsewhere in bench/ import it with
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
"""

import math

import bpy


def glint_world(scene, environment=None, color=(0.0, 0.0, 0.0)):
    """Gives `scene` a new world: the map at path `environment`, else the RGB `color`."""
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    scene.world = world
    nodes, links = world.node_tree.nodes, world.node_tree.links
    background = nodes["Background"]
    if environment is None:
        background.inputs["Color"].default_value = (*color, 1.0)
        return world
    texture = nodes.new("ShaderNodeTexEnvironment")
    texture.image = bpy.data.images.load(environment)
    texture.interpolation = "Closest"  # glint reads the nearest texel
    coords = nodes.new("ShaderNodeTexCoord")
    mapping = nodes.new("ShaderNodeMapping")
    # glint reads u = atan2(x, -z) / 2π (its frame, glTF's); Cycles' u = (π − atan2(y, x)) / 2π
    # (its frame) is glint's + 0.25 there: turn the lookup direction +90° about +Z.
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(90.0))
    links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    links.new(texture.outputs["Color"], background.inputs["Color"])
    return world

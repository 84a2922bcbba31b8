"""The simulation's colour bar, drawn over the 3D view (Coin3D through pivy, as FreeCAD's own overlays).

A vertical bar at the view's left edge from blue (gouge of the full scale) through green (on the
design) to red (leftover of the full scale), labelled in micrometres. It is one node under the
view's scene graph named COLOUR_BAR_NAME, with its own orthographic camera, drawn after the
scene (SoAnnotation) so the part never hides it; showing it again replaces the old one.

The view's scene graph is reached only through `scene_graph`, which imports pivy first: `getSceneGraph`
returns a SWIG-wrapped Coin node, and before pivy's `coin` module is loaded FreeCAD 1.0 raises "No SWIG
wrapped library loaded" and 1.1 "SWIG: Cannot find type information for requested type: SoSeparator *"
(observed; 0.20 happened to have pivy loaded already).
"""

from __future__ import annotations

import numpy as np

from spur_cad_workbench.colours import deviation_colours

COLOUR_BAR_NAME = "SpurCadColourBar"
BAR_STEPS = 40
BAR_LEFT, BAR_WIDTH, BAR_HALF_HEIGHT = 0.04, 0.07, 0.7  # in the overlay camera's units (view height = 2)


def bar_geometry(aspect: float, steps: int = BAR_STEPS) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (2 (steps + 1), 3), deviation fraction per vertex in [-1, 1]) of the bar for a view whose
    width / height is `aspect`; rows of two vertices from the bottom (gouge) to the top (leftover)."""
    fraction = np.linspace(-1.0, 1.0, steps + 1)
    y = fraction * BAR_HALF_HEIGHT
    left = -aspect + BAR_LEFT
    vertices = np.array([(x, yy, 0.0) for yy in y for x in (left, left + BAR_WIDTH)])
    return vertices, np.repeat(fraction, 2)


def _label(coin, text: str, x: float, y: float):
    node = coin.SoSeparator()
    move = coin.SoTranslation()
    move.translation = (x, y, 0.0)
    words = coin.SoText2()
    words.string = text
    node.addChild(move)
    node.addChild(words)
    return node


def colour_bar_node(scale_mm: float, aspect: float):
    """The colour bar as a Coin node (pivy), for a deviation scale of +-scale_mm."""
    from pivy import coin

    root = coin.SoAnnotation()
    root.setName(COLOUR_BAR_NAME)
    camera = coin.SoOrthographicCamera()
    camera.viewportMapping = coin.SoCamera.LEAVE_ALONE
    camera.position = (0.0, 0.0, 1.0)
    camera.height = 2.0
    camera.aspectRatio = aspect
    camera.nearDistance, camera.farDistance = 0.5, 1.5
    light = coin.SoLightModel()
    light.model = coin.SoLightModel.BASE_COLOR
    vertices, fraction = bar_geometry(aspect)
    material = coin.SoMaterial()
    material.diffuseColor.setValues(0, len(fraction), [tuple(c) for c in deviation_colours(fraction, 1.0)])
    binding = coin.SoMaterialBinding()
    binding.value = coin.SoMaterialBinding.PER_VERTEX
    points = coin.SoCoordinate3()
    points.point.setValues(0, len(vertices), [tuple(v) for v in vertices])
    mesh = coin.SoQuadMesh()
    mesh.verticesPerRow = 2
    mesh.verticesPerColumn = len(vertices) // 2
    for node in (camera, light, material, binding, points, mesh):
        root.addChild(node)
    text_colour = coin.SoBaseColor()
    text_colour.rgb = (0.1, 0.1, 0.1)
    root.addChild(text_colour)
    x = -aspect + BAR_LEFT + BAR_WIDTH + 0.02
    microns = scale_mm * 1000.0
    for text, y in ((f"+{microns:.3g} um leftover", BAR_HALF_HEIGHT), ("0 (design)", 0.0),
                    (f"-{microns:.3g} um gouge", -BAR_HALF_HEIGHT)):
        root.addChild(_label(coin, text, x, y - 0.02))
    return root


def scene_graph(view):
    """The root Coin node of a 3D view (`view.getSceneGraph()`), with pivy imported first (see above)."""
    from pivy import coin  # noqa: F401  (loads the SWIG type information getSceneGraph's result needs)

    return view.getSceneGraph()


def find_colour_bar(scene):
    """The colour bar node under `scene` (a Coin group), or None."""
    for index in range(scene.getNumChildren()):
        child = scene.getChild(index)
        if child.getName() == COLOUR_BAR_NAME:
            return child
    return None


def show_colour_bar(scale_mm: float, document) -> None:
    """Put the colour bar (replacing an older one) into the 3D view of `document`. Its width-to-height ratio
    is the view's when shown: after resizing the view, showing it again puts it back at the left edge."""
    from spur_cad_workbench.views import view_3d

    view = view_3d(document)
    if view is None:
        return
    remove_colour_bar(document)
    width, height = view.getSize()
    scene_graph(view).addChild(colour_bar_node(scale_mm, width / max(height, 1)))


def remove_colour_bar(document) -> None:
    """Take the colour bar out of the 3D view of `document` (a stale simulation has no scale to show)."""
    from spur_cad_workbench.views import view_3d

    view = view_3d(document)
    scene = scene_graph(view) if view is not None else None
    old = find_colour_bar(scene) if scene is not None else None
    if scene is not None and old is not None:
        scene.removeChild(old)

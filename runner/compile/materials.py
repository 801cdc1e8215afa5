"""Gazebo's named materials (classic `Gazebo/Red` scripts) as rgba, for URDF `<gazebo reference>` and SDF."""

from __future__ import annotations

# From gazebo's media/materials/scripts/gazebo.material (ambient/diffuse colours, rounded).
GAZEBO_MATERIALS: dict[str, tuple[float, float, float, float]] = {
    "Gazebo/White": (1.0, 1.0, 1.0, 1.0),
    "Gazebo/Black": (0.0, 0.0, 0.0, 1.0),
    "Gazebo/FlatBlack": (0.1, 0.1, 0.1, 1.0),
    "Gazebo/Grey": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/Gray": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/DarkGrey": (0.175, 0.175, 0.175, 1.0),
    "Gazebo/DarkGray": (0.175, 0.175, 0.175, 1.0),
    "Gazebo/LightGrey": (0.8, 0.8, 0.8, 1.0),
    "Gazebo/Red": (1.0, 0.0, 0.0, 1.0),
    "Gazebo/RedBright": (0.87, 0.26, 0.07, 1.0),
    "Gazebo/DarkRed": (0.5, 0.0, 0.0, 1.0),
    "Gazebo/Green": (0.0, 1.0, 0.0, 1.0),
    "Gazebo/DarkGreen": (0.0, 0.5, 0.0, 1.0),
    "Gazebo/Blue": (0.0, 0.0, 1.0, 1.0),
    "Gazebo/SkyBlue": (0.53, 0.81, 0.92, 1.0),
    "Gazebo/DarkBlue": (0.0, 0.0, 0.5, 1.0),
    "Gazebo/Yellow": (1.0, 1.0, 0.0, 1.0),
    "Gazebo/DarkYellow": (0.7, 0.7, 0.0, 1.0),
    "Gazebo/Orange": (1.0, 0.5088, 0.0468, 1.0),
    "Gazebo/Purple": (1.0, 0.0, 1.0, 1.0),
    "Gazebo/Turquoise": (0.0, 1.0, 1.0, 1.0),
    "Gazebo/Indigo": (0.33, 0.0, 0.5, 1.0),
    "Gazebo/Gold": (0.8, 0.64, 0.2, 1.0),
    "Gazebo/Wood": (0.6, 0.42, 0.2, 1.0),
    "Gazebo/WoodFloor": (0.55, 0.4, 0.25, 1.0),
    "Gazebo/WoodPallet": (0.55, 0.4, 0.25, 1.0),
    "Gazebo/Bricks": (0.65, 0.3, 0.2, 1.0),
    "Gazebo/CeilingTiled": (0.9, 0.9, 0.9, 1.0),
    "Gazebo/PaintedWall": (0.9, 0.88, 0.85, 1.0),
    "Gazebo/Road": (0.3, 0.3, 0.3, 1.0),
    "Gazebo/Residential": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/Tertiary": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/Pedestrian": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/Footway": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/Motorway": (0.3, 0.3, 0.3, 1.0),
    "Gazebo/Lanes": (0.3, 0.3, 0.3, 1.0),
    "Gazebo/Trunk": (0.3, 0.3, 0.3, 1.0),
    "Gazebo/Primary": (0.3, 0.3, 0.3, 1.0),
    "Gazebo/Secondary": (0.3, 0.3, 0.3, 1.0),
    "Gazebo/Grass": (0.25, 0.55, 0.2, 1.0),
    "Gazebo/GreyTransparent": (0.5, 0.5, 0.5, 0.5),
    "Gazebo/RedTransparent": (1.0, 0.0, 0.0, 0.5),
    "Gazebo/GreenTransparent": (0.0, 1.0, 0.0, 0.5),
    "Gazebo/BlueTransparent": (0.0, 0.0, 1.0, 0.5),
    "Gazebo/DarkMagentaTransparent": (0.6, 0.0, 0.6, 0.5),
    "Gazebo/BlueGlow": (0.0, 0.0, 1.0, 1.0),
    "Gazebo/OrangeTransparent": (1.0, 0.5, 0.0, 0.4),
    "Gazebo/ZincYellow": (0.9725, 0.9529, 0.2078, 1.0),
    "Gazebo/Chrome": (0.8, 0.8, 0.8, 1.0),
    "Gazebo/BuildingFrame": (0.9, 0.9, 0.9, 1.0),
    "Gazebo/Grid": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/WhiteGlow": (1.0, 1.0, 1.0, 1.0),
    "Gazebo/LightGray": (0.8, 0.8, 0.8, 1.0),
    "Gazebo/RedGlow": (1.0, 0.0, 0.0, 1.0),
    "Gazebo/GreenGlow": (0.0, 1.0, 0.0, 1.0),
    "Gazebo/BlueLaser": (0.0, 0.0, 1.0, 0.6),
    "Gazebo/YellowGlow": (1.0, 1.0, 0.0, 1.0),
    "Gazebo/YellowTransparent": (1.0, 1.0, 0.0, 0.5),
    "Gazebo/PurpleGlow": (1.0, 0.0, 1.0, 1.0),
    "Gazebo/TurquoiseGlow": (0.0, 1.0, 1.0, 1.0),
    "Gazebo/GrassFloor": (0.3, 0.55, 0.2, 1.0),
    "Gazebo/Asphalt": (0.25, 0.25, 0.25, 1.0),
    "Gazebo/Pioneer2Body": (0.5, 0.0, 0.0, 1.0),
    "Gazebo/PioneerBody": (0.5, 0.0, 0.0, 1.0),
}


def gazebo_material(name: str) -> tuple[float, float, float, float] | None:
    """rgba of a Gazebo material name, case-insensitively; None if unknown."""
    name = name.strip()
    if name in GAZEBO_MATERIALS:
        return GAZEBO_MATERIALS[name]
    return _LOWER.get(name.lower())


_LOWER = {k.lower(): v for k, v in GAZEBO_MATERIALS.items()}

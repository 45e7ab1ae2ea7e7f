"""
A faceted body's surface: the force and torque of solar radiation pressure and of drag.

The body is a set of flat facets, each with an area A (m^2), an outward unit
normal n and a centre of pressure c (m, body frame, from the centre of mass),
its reflection coefficients (specular rho_s, diffuse rho_d; absorbed
1 - rho_s - rho_d) and its drag coefficient C_D. A facet acts only when it
faces the Sun or the flow (cos theta > 0); self-shadowing between facets is not
modelled (exact for a convex body).

Solar radiation pressure (Montenbruck and Gill, *Satellite Orbits*, section
3.4.1): with s the unit vector from the body to the Sun (body frame), P the
pressure there (N/m^2: the solar constant over the speed of light, scaled by
(1 au / d)^2 and by the sunlit fraction of the shadow), cos theta = n . s,

    F = -P A cos theta [(1 - rho_s) s + 2 (rho_s cos theta + rho_d / 3) n]

Drag (as Basilisk's facetDragDynamicEffector, the flat-plate free-molecular
model): with v the body's velocity relative to the atmosphere (body frame, m/s)
and rho the density (kg/m^3), cos theta = n . v / |v|,

    F = -1/2 rho |v|^2 C_D A cos theta v / |v|

Each facet's torque is c x F (N m, body frame); the body's is their sum.
"""

import numpy as np

from .sun import AU

#: The total solar irradiance at 1 au (W/m^2; Kopp and Lean, Geophys. Res. Lett. 38, 2011).
SOLAR_IRRADIANCE = 1361.0
#: The speed of light (m/s).
SPEED_OF_LIGHT = 299792458.0
#: The solar radiation pressure at 1 au on an absorbing surface facing the Sun (N/m^2).
SOLAR_PRESSURE_1AU = SOLAR_IRRADIANCE / SPEED_OF_LIGHT
#: The numbers per facet in the flat ``facets`` list, in order.
FACET_FIELDS = ('area', 'nx', 'ny', 'nz', 'cx', 'cy', 'cz', 'specular', 'diffuse', 'drag')


class Facets:
    """
    Flat facets of a body, from a flat list of ``len(FACET_FIELDS)`` numbers per facet.

    Per facet: area (m^2, > 0), the outward normal (body frame; normalised here,
    not zero), the centre of pressure (m, body frame, from the centre of mass),
    the specular and diffuse reflection coefficients (each >= 0, their sum <= 1)
    and the drag coefficient (>= 0). Refuses (ValueError naming ``facets`` and the
    facet) what is not that.
    """

    def __init__(self, values):
        n = len(FACET_FIELDS)
        try:
            flat = np.array([float(v) for v in values], dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f'facets must be numbers, {n} per facet '
                             f'({", ".join(FACET_FIELDS)}), got {values!r}') from None
        if flat.size == 0 or flat.size % n:
            raise ValueError(f'facets must hold {n} numbers per facet '
                             f'({", ".join(FACET_FIELDS)}), got {flat.size}')
        rows = flat.reshape(-1, n)
        for k, row in enumerate(rows):
            area, normal, specular, diffuse, drag = row[0], row[1:4], row[7], row[8], row[9]
            where = f'facets: facet {k}'
            if not np.all(np.isfinite(row)):
                raise ValueError(f'{where} has a non-finite number: {row.tolist()}')
            if not area > 0.0:
                raise ValueError(f'{where} needs an area > 0 m^2, got {area:g}')
            if not np.linalg.norm(normal) > 0.0:
                raise ValueError(f'{where} needs a non-zero normal')
            if specular < 0.0 or diffuse < 0.0 or specular + diffuse > 1.0:
                raise ValueError(f'{where} needs specular, diffuse >= 0 with a sum <= 1, '
                                 f'got {specular:g}, {diffuse:g}')
            if drag < 0.0:
                raise ValueError(f'{where} needs a drag coefficient >= 0, got {drag:g}')
        self.area = rows[:, 0].copy()
        self.normal = rows[:, 1:4] / np.linalg.norm(rows[:, 1:4], axis=1)[:, None]
        self.centre = rows[:, 4:7].copy()
        self.specular = rows[:, 7].copy()
        self.diffuse = rows[:, 8].copy()
        self.drag = rows[:, 9].copy()

    def __len__(self):
        return len(self.area)

    def turned(self, turn):
        """
        Return these facets with normals and centres given in another frame.

        ``turn(v)`` maps a vector of this frame to the other (a rotation, e.g. the body
        frame to the principal frame of the inertia).
        """
        out = object.__new__(Facets)
        out.area, out.specular, out.diffuse, out.drag = (
            self.area, self.specular, self.diffuse, self.drag)
        out.normal = np.array([turn(n) for n in self.normal], dtype=float).reshape(-1, 3)
        out.centre = np.array([turn(c) for c in self.centre], dtype=float).reshape(-1, 3)
        return out

    def solar_pressure(self, sun, pressure):
        """
        Return (force (N), torque (N m)) of solar radiation pressure, body frame.

        ``sun``: the direction from the body to the Sun (body frame; normalised
        here); ``pressure`` (N/m^2): the pressure where the body is, the shadow's
        fraction included (e.g. ``SOLAR_PRESSURE_1AU * (au / d)^2 * light``).
        """
        s = np.asarray(sun, dtype=float)
        s = s / np.linalg.norm(s)
        cos = np.maximum(self.normal @ s, 0.0)
        along_s = -pressure * self.area * cos * (1.0 - self.specular)
        along_n = -2.0 * pressure * self.area * cos * (self.specular * cos + self.diffuse / 3.0)
        forces = along_s[:, None] * s + along_n[:, None] * self.normal
        return forces.sum(axis=0), np.cross(self.centre, forces).sum(axis=0)

    def drag_force(self, velocity, density):
        """
        Return (force (N), torque (N m)) of drag, body frame.

        ``velocity`` (m/s, body frame): the body's velocity relative to the
        atmosphere; ``density`` (kg/m^3). Zero at zero velocity.
        """
        v = np.asarray(velocity, dtype=float)
        speed = float(np.linalg.norm(v))
        if speed == 0.0:
            return np.zeros(3), np.zeros(3)
        u = v / speed
        cos = np.maximum(self.normal @ u, 0.0)
        size = -0.5 * density * speed * speed * self.drag * self.area * cos
        forces = size[:, None] * u
        return forces.sum(axis=0), np.cross(self.centre, forces).sum(axis=0)


def solar_pressure_at(distance, light=1.0):
    """
    Return the solar radiation pressure (N/m^2) at a distance from the Sun.

    ``distance`` (m) from the Sun's centre; ``light`` the sunlit fraction (0 to 1).
    """
    return SOLAR_PRESSURE_1AU * (AU / distance) ** 2 * light


def box(size, centre_of_mass=(0.0, 0.0, 0.0), specular=0.0, diffuse=0.0, drag=2.2):
    """
    Return the flat ``facets`` list of the six faces of a box, for :class:`Facets`.

    ``size`` (m, x, y, z edges), centred on the origin of the body frame;
    ``centre_of_mass`` (m, body frame) where the centre of mass is (the centres
    of pressure are given from it); the coefficients the same on every face.
    """
    a = [float(c) for c in size]
    m = [float(c) for c in centre_of_mass]
    out = []
    for axis in range(3):
        area = a[(axis + 1) % 3] * a[(axis + 2) % 3]
        for sign in (1.0, -1.0):
            normal = [0.0, 0.0, 0.0]
            normal[axis] = sign
            centre = [-c for c in m]
            centre[axis] += sign * a[axis] / 2.0
            out += [area, *normal, *centre, specular, diffuse, drag]
    return out

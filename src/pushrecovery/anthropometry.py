"""A person's body parameters from mass, stature and sex (de Leva 1996; Winter 2009).

:func:`person_params` scales the segment table of de Leva (1996, Table 4) to a person and
derives the quantities :class:`~pushrecovery.params.BodyParams` needs: the CoM height above
the ankle, the leg length, the foot, and the upper body's (head, trunk, arms) moments of inertia
about the hip axes. What the tables do not give (the hip's strength and range, the stance) is
kept from a base body and said so in :attr:`PersonBody.sources`: nothing is silently a robot's.

References
----------
de Leva P. (1996). Adjustments to Zatsiorsky-Seluyanov's segment inertia parameters.
J Biomech 29(9):1223-1230, Table 4 (young adults: 100 women of mean stature 1.735 m and mass
61.9 kg, 15 men of 1.741 m and 73.0 kg).

Winter D. A. (2009). Biomechanics and Motor Control of Human Movement, 4th ed., Fig. 4.1
(segment lengths as fractions of stature H, after Drillis & Contini 1966): ankle height
0.039 H, foot width 0.055 H.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from types import MappingProxyType
from typing import Literal, NamedTuple

from pushrecovery.arguments import bounded_float, finite_float, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import LIMITS, BodyParams

__all__ = [
    "ANKLE_HEIGHT",
    "DE_LEVA",
    "FOOT_WIDTH",
    "SEXES",
    "PersonBody",
    "Segment",
    "person_params",
]

SEXES = ("female", "male")
Sex = Literal["female", "male"]


class Segment(NamedTuple):
    """One row of de Leva's Table 4 (lengths in mm, the rest in % as printed).

    ``length`` is the mean distance between the endpoints [mm] in the sample of stature
    :data:`STATURE`; ``mass`` the segment's share of body mass [%]; ``com`` the CoM's distance
    from the first (proximal or cranial) endpoint [% of length]; ``r_sag``, ``r_trans``,
    ``r_long`` the radii of gyration about the sagittal (antero-posterior), transverse
    (medio-lateral) and longitudinal axes through the segment's CoM [% of length].
    """

    length: float
    mass: float
    com: float
    r_sag: float
    r_trans: float
    r_long: float


#: de Leva (1996) Table 4, per sex. Endpoints (first -> second): head VERT -> CERV (vertex to
#: C7), trunk CERV -> MIDH (mid hip joint centres), trunk_shoulders MIDS -> MIDH (mid shoulder
#: joint centres; only its length is used: the shoulders' height above the hips), upper_arm
#: SJC -> EJC, forearm EJC -> WJC, hand WJC -> MET3, thigh HJC -> KJC, shank KJC -> AJC (ankle
#: joint centre), foot HEEL -> TTIP. Head, trunk and shank are the table's alternative
#: endpoints (its lower half), chosen so that the chain ankle-knee-hip-C7-vertex is joint to joint.
DE_LEVA: MappingProxyType[str, MappingProxyType[str, Segment]] = MappingProxyType(
    {
        "female": MappingProxyType(
            {
                "head": Segment(243.7, 6.68, 48.41, 27.1, 29.5, 26.1),
                "trunk": Segment(614.8, 42.57, 49.64, 30.7, 29.2, 14.7),
                "trunk_shoulders": Segment(497.9, 42.57, 37.82, 37.9, 36.1, 18.2),
                "upper_arm": Segment(275.1, 2.55, 57.54, 27.8, 26.0, 14.8),
                "forearm": Segment(264.3, 1.38, 45.59, 26.1, 25.7, 9.4),
                "hand": Segment(78.0, 0.56, 74.74, 53.1, 45.4, 33.5),
                "thigh": Segment(368.5, 14.78, 36.12, 36.9, 36.4, 16.2),
                "shank": Segment(438.6, 4.81, 43.52, 26.7, 26.3, 9.2),
                "foot": Segment(228.3, 1.29, 40.14, 29.9, 27.9, 13.9),
            }
        ),
        "male": MappingProxyType(
            {
                "head": Segment(242.9, 6.94, 50.02, 30.3, 31.5, 26.1),
                "trunk": Segment(603.3, 43.46, 51.38, 32.8, 30.6, 16.9),
                "trunk_shoulders": Segment(515.5, 43.46, 43.10, 38.4, 35.8, 19.7),
                "upper_arm": Segment(281.7, 2.71, 57.72, 28.5, 26.9, 15.8),
                "forearm": Segment(268.9, 1.62, 45.74, 27.6, 26.5, 12.1),
                "hand": Segment(86.2, 0.61, 79.00, 62.8, 51.3, 40.1),
                "thigh": Segment(422.2, 14.16, 40.95, 32.9, 32.9, 14.9),
                "shank": Segment(440.3, 4.33, 43.95, 25.1, 24.6, 10.2),
                "foot": Segment(258.1, 1.37, 44.15, 25.7, 24.5, 12.4),
            }
        ),
    }
)
#: Mean stature of de Leva's samples [mm] (the lengths above are theirs).
STATURE = MappingProxyType({"female": 1735.0, "male": 1741.0})
#: Winter (2009) Fig. 4.1: height of the ankle joint above the floor and foot width, as
#: fractions of stature H (Drillis & Contini 1966).
ANKLE_HEIGHT = 0.039
FOOT_WIDTH = 0.055
#: Assumed distance of the ankle from the heel, as a fraction of foot length (no table gives
#: it; the built-in preset's 5 cm of a 20 cm foot).
ANKLE_FROM_HEEL = 0.25

_DE_LEVA = "de Leva 1996 Table 4"
_WINTER = "Winter 2009 Fig. 4.1"
#: The fields the tables do not give: kept from the base body, said so.
_NOT_A_PERSON = (
    "torque_max",
    "flywheel_angle_max",
    "torque_max_roll",
    "flywheel_angle_max_roll",
    "stance_width",
    "min_step_time",
)
#: Below this stature [m] the adult fractions are an extrapolation (children's proportions).
ADULT_STATURE = 1.4


@dataclass(frozen=True, slots=True)
class PersonBody:
    """A person's body: the parameters and where each came from.

    Attributes
    ----------
    params : BodyParams
        The body, ready for every model and the analysis.
    sources : dict of str to str
        For every field of ``params``: the table it was computed from (``de Leva 1996 Table
        4``, ``Winter 2009 Fig. 4.1``), ``assumption: ...``, ``given`` or ``base body ...``
        (kept from the base: not a person's value). ``model`` says the sample and any
        extrapolation.
    upper_mass : float
        Mass of the head, trunk and both arms [kg].
    upper_com_above_hip : float
        Height of their CoM above the hip joint centres, standing [m].
    segment_masses : dict of str to float
        Mass of each segment [kg] (arms and legs: one side).
    """

    params: BodyParams
    sources: dict[str, str]
    upper_mass: float
    upper_com_above_hip: float
    segment_masses: dict[str, float]


def person_params(
    mass: float,
    height: float,
    sex: str,
    *,
    base: BodyParams | None = None,
    ankle_from_heel: float = ANKLE_FROM_HEEL,
) -> PersonBody:
    r"""Return a person's body parameters from mass, stature and sex.

    Each segment i of de Leva's Table 4 (:data:`DE_LEVA`) has mass :math:`m_i = f_i m`, length
    :math:`L_i = (\ell_i / S) H` (the sample's length :math:`\ell_i` scaled by stature, S the
    sample's mean stature) and, standing upright with the arms hanging, a CoM at height
    :math:`z_i` above the ankle joint (z up) on the line of its endpoints, at :math:`c_i L_i`
    from the first endpoint. With the hip at :math:`z_h = L_{shank} + L_{thigh}` and the
    shoulders at :math:`z_h + L_{MIDS-MIDH}`:

    - ``com_height`` :math:`L = \sum_i m_i z_i / \sum_i m_i` (both arms and legs; the feet's
      CoM on the floor, :math:`z = -0.039 H`);
    - ``leg_length`` (floor to hip joint) :math:`0.039 H + L_{shank} + L_{thigh}` (Winter's
      ankle height);
    - ``flywheel_inertia`` (head, trunk and arms about the medio-lateral axis through the hip
      joint centres, pitch) :math:`I = \sum_u m_u [(r_{trans,u} L_u)^2 + (z_u - z_h)^2]`;
      ``flywheel_inertia_roll`` the same with the sagittal (antero-posterior) radius, the arms'
      sideways offset from the midline neglected (not in the table: a lower bound, by about
      m_arms (shoulder half-width)^2, some 3 %);
    - the foot: length :math:`L_{foot}`, ``heel`` :math:`= -a L_{foot}`, ``toe``
      :math:`= (1 - a) L_{foot}` with the ankle at :math:`a` = ``ankle_from_heel`` of the
      length from the heel (an assumption: no table gives it), ``foot_width`` :math:`0.055 H`.

    The hip's torque limit and range, the stance width and the step timing are no
    anthropometric quantities: they are kept from ``base`` and marked so in ``sources``
    (give measured values instead where the study needs them).

    Parameters
    ----------
    mass : float
        Body mass m [kg], in [0.01, 500] (0.01: :data:`~pushrecovery.params.LIMITS`' lowest).
    height : float
        Stature H [m], in [0.5, 2.5].
    sex : {"female", "male"}
        Which of de Leva's columns.
    base : BodyParams, optional
        The body whose other fields (gravity, hip limits, stance, steps) are kept; default the
        built-in ``paper`` preset.
    ankle_from_heel : float, optional
        Distance of the ankle joint from the heel as a fraction of foot length, in (0, 1);
        default 0.25 (assumed).

    Returns
    -------
    PersonBody
        The parameters and their sources.

    Raises
    ------
    InvalidParameterError
        A value out of its range, or another sex, naming the parameter.

    References
    ----------
    de Leva (1996), J Biomech 29(9):1223-1230, Table 4; Winter (2009), Biomechanics and Motor
    Control of Human Movement, 4th ed., Fig. 4.1.
    """
    mass = bounded_float("mass", mass, LIMITS["mass"][0], 500.0, "kg")  # a body's, at least
    height = bounded_float("height", height, 0.5, 2.5, "m")
    if not (isinstance(sex, str) and sex in SEXES):
        raise InvalidParameterError(f"sex must be 'female' or 'male', got {str(sex)[:20]!r}")
    ankle_from_heel = finite_float("ankle_from_heel", ankle_from_heel)
    if not 0.0 < ankle_from_heel < 1.0:
        raise InvalidParameterError(f"ankle_from_heel must be in (0, 1), got {ankle_from_heel:g}")
    if base is not None:
        require_type("base", base, BodyParams)
    if base is None:
        from pushrecovery.presets import load_params

        base = load_params()
        base_name = "base body: the built-in 'paper' preset"
    else:
        base_name = "base body given"
    table = DE_LEVA[sex]

    def length(name: str) -> float:
        return table[name].length / STATURE[sex] * height

    def seg_mass(name: str) -> float:
        return table[name].mass / 100.0 * mass

    ankle_height = ANKLE_HEIGHT * height
    hip = length("shank") + length("thigh")
    shoulder = hip + length("trunk_shoulders")
    elbow = shoulder - length("upper_arm")
    wrist = elbow - length("forearm")
    # CoM heights above the ankle joint, each c_i L_i from its first endpoint.
    heights = {
        "head": hip + length("trunk") + length("head") * (1.0 - table["head"].com / 100.0),
        "trunk": hip + length("trunk") * (1.0 - table["trunk"].com / 100.0),
        "upper_arm": shoulder - length("upper_arm") * table["upper_arm"].com / 100.0,
        "forearm": elbow - length("forearm") * table["forearm"].com / 100.0,
        "hand": wrist - length("hand") * table["hand"].com / 100.0,
        "thigh": hip - length("thigh") * table["thigh"].com / 100.0,
        "shank": length("shank") * (1.0 - table["shank"].com / 100.0),
        "foot": -ankle_height,
    }
    count = {"head": 1, "trunk": 1}  # every other segment twice (left and right)
    masses = {name: seg_mass(name) for name in heights}
    total = sum(masses[n] * count.get(n, 2) for n in heights)
    com = sum(masses[n] * count.get(n, 2) * heights[n] for n in heights) / total
    upper = ("head", "trunk", "upper_arm", "forearm", "hand")
    upper_mass = sum(masses[n] * count.get(n, 2) for n in upper)
    upper_com = sum(masses[n] * count.get(n, 2) * (heights[n] - hip) for n in upper) / upper_mass

    def inertia(radius: str) -> float:
        return sum(
            masses[n]
            * count.get(n, 2)
            * ((getattr(table[n], radius) / 100.0 * length(n)) ** 2 + (heights[n] - hip) ** 2)
            for n in upper
        )

    foot = length("foot")
    values = asdict(base)
    derived = {
        "mass": mass,
        "com_height": com,
        "leg_length": ankle_height + hip,
        "max_step_length": None,  # the base's tie: equal to the leg length
        "heel": -ankle_from_heel * foot,
        "toe": (1.0 - ankle_from_heel) * foot,
        "foot_width": FOOT_WIDTH * height,
        "foot_polygon": None,
        "flywheel_inertia": inertia("r_trans"),
        "flywheel_inertia_roll": inertia("r_sag"),
    }
    values.update(derived)
    params = BodyParams(**values)
    sources = {name: base_name for name in values}
    sources.update(
        {
            "mass": "given",
            "com_height": f"{_DE_LEVA} (segment CoMs standing, arms hanging)",
            "leg_length": f"{_WINTER} (ankle height 0.039 H) + {_DE_LEVA} (shank, thigh)",
            "max_step_length": "equal to leg_length (the base body's tie)",
            "heel": f"{_DE_LEVA} (foot length); assumption: ankle at {ankle_from_heel:g} "
            "of the foot from the heel",
            "toe": f"{_DE_LEVA} (foot length); assumption: ankle at {ankle_from_heel:g} "
            "of the foot from the heel",
            "foot_width": f"{_WINTER} (0.055 H)",
            "foot_polygon": "none: a rectangular foot",
            "flywheel_inertia": f"{_DE_LEVA} (head, trunk, arms about the hip's "
            "medio-lateral axis, transverse radii)",
            "flywheel_inertia_roll": f"{_DE_LEVA} (head, trunk, arms about the hip's "
            "antero-posterior axis, sagittal radii; arms' sideways offset neglected)",
        }
    )
    for name in _NOT_A_PERSON:
        sources[name] = f"{base_name}; NOT a person's value (no anthropometric table gives it)"
    sample = "young adults (de Leva's samples)"
    if height < ADULT_STATURE:
        sample += f"; EXTRAPOLATED to a stature of {height:g} m (a child's proportions differ)"
    sources["model"] = f"{_DE_LEVA}, {sex}; {sample}"
    return PersonBody(
        params=params,
        sources=sources,
        upper_mass=upper_mass,
        upper_com_above_hip=upper_com,
        segment_masses=masses,
    )

"""The method's impact stress of a stream falling from a belt (pure maths, SI units, no pycal
imports): used by the lab analysis (`pycal impact`, `pycal analyse`) and by the transfer rig's
stream geometry (pycal/rigs/transfer/stream.py)."""
import math

G_M_S2 = 9.81


def min_drop_height_m(belt_speed_m_s, g_m_s2=G_M_S2):
    """Lowest drop height (m) where the impact-stress rule holds: vz = v0, H = v0^2 / (2 g)."""
    return belt_speed_m_s ** 2 / (2.0 * g_m_s2)


def impact_stress(drop_height_m, belt_speed_m_s, mass_flow_kg_s, bulk_density_kg_m3, g_m_s2=G_M_S2):
    """Impact stress of a stream falling from a belt onto the receiving point (SI units).

    The stream leaves the belt horizontally at the belt speed v0 (m/s) with bulk density
    rho0 (kg/m3) and falls H (m): vertical velocity vz = sqrt(2 g H). Only the vertical
    velocity counts: the stream keeps its cross-section and its mass flow while it
    accelerates, so rho_b vz = rho0 v0 and rho_b = rho0 v0 / vz (kg/m3). Impact stress
    P = rho_b vz^2 sin^2(theta) with theta = 90 deg, i.e. P = rho0 v0 vz (Pa).
    The rule holds once the stream falls faster than it left the belt (vz >= v0, i.e.
    H >= min_drop_height_m(v0) = v0^2 / (2 g)); below, it would make the stream denser
    than on the belt, and a ValueError says so.
    Returns a dict: impact_velocity_vertical_m_s, impact_speed_m_s (sqrt(v0^2 + vz^2),
    for information only), stream_bulk_density_kg_m3, stream_area_m2 (= Q / (rho0 v0)),
    impact_stress_pa."""
    for name, value in (("drop_height_m", drop_height_m), ("belt_speed_m_s", belt_speed_m_s),
                        ("mass_flow_kg_s", mass_flow_kg_s), ("bulk_density_kg_m3", bulk_density_kg_m3)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} = {value} must be > 0")
    vz = math.sqrt(2.0 * g_m_s2 * drop_height_m)
    h_min = min_drop_height_m(belt_speed_m_s, g_m_s2)
    if drop_height_m < h_min:
        raise ValueError(f"drop_height_m = {drop_height_m:g} is below v0^2 / (2 g) = {h_min:.3g} m at a belt "
                         f"speed of {belt_speed_m_s:g} m/s: the stream would be denser than on the belt "
                         "(rho_b = rho0 v0 / vz > rho0), the impact-stress rule does not apply")
    rho_b = bulk_density_kg_m3 * belt_speed_m_s / vz
    theta = math.radians(90.0)
    return {
        "impact_velocity_vertical_m_s": vz,
        "impact_speed_m_s": math.hypot(belt_speed_m_s, vz),
        "stream_bulk_density_kg_m3": rho_b,
        "stream_area_m2": mass_flow_kg_s / (bulk_density_kg_m3 * belt_speed_m_s),
        "impact_stress_pa": rho_b * vz ** 2 * math.sin(theta) ** 2,
    }

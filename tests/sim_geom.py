"""sim_geom.py -- plane geometry shared by the tests that check sonard against sonar-sim's walls (stdlib only)."""


def ray_segment(ux, uy, x0, y0, x1, y1):
    """Distance along the unit ray (ux, uy) from the origin to the segment (x0, y0)-(x1, y1); None if missed."""
    ex, ey = x1 - x0, y1 - y0
    den = ux * ey - uy * ex
    if abs(den) < 1e-12:
        return None
    t = (x0 * ey - y0 * ex) / den
    s = (x0 * uy - y0 * ux) / den
    return t if t > 0 and 0 <= s <= 1 else None

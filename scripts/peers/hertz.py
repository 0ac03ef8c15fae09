"""Hertz closed forms and the profile fit contactlink itself reports
(src/hertz.rs): least squares of p^2 = p0^2 (1 - s^2/w^2) in (s^2, p^2)
over the points inside 90 % of the loaded zone, s = |x| for the line
contact, sqrt(x^2 + y^2) for the point contact."""
import math


def fit_profile(points, ps, point=False):
    """(p0, w) of the pressures ps at points [(x, y, z)], or None."""
    loaded = [((x * x + y * y) if point else x * x, p)
              for (x, y, _), p in zip(points, ps) if p > 0.0]
    if len(loaded) < 3:
        return None
    s2_max = max(s for s, _ in loaded)
    inner = [(s, p * p) for s, p in loaded if s <= 0.81 * s2_max]
    n = len(inner)
    if n < 3:
        return None
    mx = sum(s for s, _ in inner) / n
    my = sum(q for _, q in inner) / n
    sxx = sum((s - mx) ** 2 for s, _ in inner)
    sxy = sum((s - mx) * (q - my) for s, q in inner)
    if sxx <= 0:
        return None
    slope = sxy / sxx
    icpt = my - slope * mx
    if icpt <= 0 or slope >= 0:
        return None
    return math.sqrt(icpt), math.sqrt(icpt / -slope)


def effective_modulus(youngs, poisson):
    """E* of two bodies of the same material."""
    return 1.0 / (2.0 * (1.0 - poisson ** 2) / youngs)


def line(load, radius, e_star):
    """(b, p0) for a load per unit length."""
    b = math.sqrt(4 * load * radius / (math.pi * e_star))
    return b, 2 * load / (math.pi * b)


def point(force, radius, e_star):
    """(a, p0) for a total force."""
    a = (3 * force * radius / (4 * e_star)) ** (1.0 / 3.0)
    return a, 3 * force / (2 * math.pi * a * a)


def errors(exact, p0, w):
    """(p0 error, width error), relative, against exact = (w, p0)."""
    w_exact, p0_exact = exact
    return (p0 - p0_exact) / p0_exact, (w - w_exact) / w_exact

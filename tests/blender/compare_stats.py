"""The statistics of the Hairis-against-Cycles tests (test_cycles_compare, test_cycles_hdri).

Both engines render SEEDS independent images. Per block×block pixels and channel,
d = mean_hairis − mean_cycles and its variance s² = (var_h + var_c)/SEEDS come from the seeds,
so t = d/s follows Student's t with about 2(SEEDS−1) degrees of freedom when both engines
converge to the same image. :func:`compare` asserts
  * each channel's image mean agrees within 2%,
  * the mean of t² over the blocks is within its expectation ν/(ν−2) plus five standard errors
    (a bound derived from the measured noise, not a tolerance picked by hand),
  * no block is beyond the t quantile at α = 0.01 with a Šidák correction over the blocks.
"""

import math

import numpy as np


def downsample(images, factor):
    """Means over factor×factor blocks of a (seeds, height, width, 3) stack."""
    s, h, w, c = images.shape
    return images.reshape(s, h // factor, factor, w // factor, factor, c).mean(axis=(2, 4))


def student_t_sf(t, dof):
    """P(T > t) for Student's t with ``dof`` degrees of freedom (numerical integration)."""
    x = np.linspace(0.0, t, 20001)
    log_c = (math.lgamma((dof + 1) / 2) - math.lgamma(dof / 2)
             - 0.5 * math.log(dof * math.pi))
    density = np.exp(log_c - (dof + 1) / 2 * np.log1p(x * x / dof))
    return 0.5 - np.trapz(density, x)


def t_critical(alpha_two_sided, dof):
    """t with P(|T| > t) = alpha for Student's t (bisection)."""
    lo, hi = 0.0, 1000.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if 2.0 * student_t_sf(mid, dof) > alpha_two_sided:
            lo = mid
        else:
            hi = mid
    return hi


def compare(cycles, hairis, block=4):
    """The three assertions of the module docstring on (seeds, height, width, 3) stacks;
    returns the figures (channel ratios, mean t², max |t| and their bounds)."""
    seeds = cycles.shape[0]
    cycles_mean = cycles.reshape(seeds, -1, 3).mean(axis=(0, 1))
    hairis_mean = hairis.reshape(seeds, -1, 3).mean(axis=(0, 1))
    ratio = hairis_mean / cycles_mean
    print("channel means: cycles %s hairis %s ratio %s" % (cycles_mean, hairis_mean, ratio))
    assert np.all(np.abs(ratio - 1.0) <= 0.02), "channel means differ by more than 2%%: %s" % ratio

    c, h = downsample(cycles, block), downsample(hairis, block)
    difference = h.mean(axis=0) - c.mean(axis=0)
    variance = (h.var(axis=0, ddof=1) + c.var(axis=0, ddof=1)) / seeds
    # Blocks of pure background are constant in both engines: no noise to compare with, so
    # they must agree to float precision instead.
    flat = variance <= 1e-12
    assert np.all(np.abs(difference[flat]) <= 1e-5 * np.maximum(1.0, np.abs(c.mean(0)[flat]))), \
        "noise-free blocks differ: %s" % np.abs(difference[flat]).max()
    t = difference[~flat] / np.sqrt(variance[~flat])
    dof = 2 * (seeds - 1)
    # t² ~ F(1, ν): mean ν/(ν−2), variance 2ν²(ν−1)/((ν−2)²(ν−4)). Channels of a block are
    # correlated, so the standard error counts blocks, not block-channels.
    mean_t2 = dof / (dof - 2.0)
    var_t2 = 2.0 * dof ** 2 * (dof - 1) / ((dof - 2.0) ** 2 * (dof - 4.0))
    blocks = t.size / 3.0
    bound = mean_t2 + 5.0 * math.sqrt(var_t2 / blocks)
    observed = float(np.mean(t * t))
    relative_rms = math.sqrt(float(np.mean(difference ** 2))) / float(c.mean())
    noise_rms = math.sqrt(float(np.mean(variance))) / float(c.mean())
    print("%dx%d blocks: %d noisy, mean t^2 %.3f (expected %.3f, bound %.3f), max |t| %.2f; "
          "relative RMS difference %.4f against noise %.4f"
          % (block, block, t.size, observed, mean_t2, bound, float(np.abs(t).max()),
             relative_rms, noise_rms))
    assert observed <= bound, "the difference image is beyond the noise: mean t^2 %.3f > %.3f" \
        % (observed, bound)
    alpha = 1.0 - (1.0 - 0.01) ** (1.0 / t.size)
    critical = t_critical(alpha, dof)
    worst = float(np.abs(t).max())
    print("Sidak: per-block alpha %.2e, |t| bound %.2f" % (alpha, critical))
    assert worst <= critical, "a block differs beyond the noise: |t| = %.2f > %.2f" \
        % (worst, critical)
    return {"ratio": ratio, "mean_t2": observed, "mean_t2_bound": bound, "max_t": worst,
            "max_t_bound": critical}


# ---- Hair pixels: power-sized comparison of their means --------------------------------------
#
# The block tests above dilute a bias confined to the hair among the other pixels. Here only
# the pixels a hair mask marks count: per seed and channel the mean over those pixels, then a
# Welch t test of Hairis' seed means against Cycles'. Its power is computed, not assumed: from
# the seed-to-seed variances measured in the same renders, the smallest relative bias the test
# finds with the asked power at its false-alarm level (the noncentral t, Welch's degrees of
# freedom) must not exceed the bias the test claims to see.

def _integrate(values, x):
    """The trapezoidal rule (np.trapz is deprecated from NumPy 2)."""
    return float(np.sum(0.5 * (values[1:] + values[:-1]) * np.diff(x)))


def t_power(shift, dof, critical):
    """P(|T| > critical) for the noncentral t T = (Z + shift)/sqrt(V/dof), V ~ χ²(dof): the
    power of a two-sided t test against a true difference of ``shift`` standard errors."""
    upper = dof + 40.0 * math.sqrt(2.0 * dof) + 40.0
    v = np.linspace(upper / 40000.0, upper, 40000)
    half = 0.5 * dof
    density = np.exp((half - 1.0) * np.log(v) - 0.5 * v - half * math.log(2.0)
                     - math.lgamma(half))
    scale = critical * np.sqrt(v / dof)
    erf = np.vectorize(math.erf)
    reject = (0.5 * (1.0 + erf((shift - scale) / math.sqrt(2.0)))
              + 0.5 * (1.0 + erf((-shift - scale) / math.sqrt(2.0))))
    return _integrate(reject * density, v) / _integrate(density, v)


def detectable_shift(dof, alpha, power=0.9):
    """The true difference, in standard errors, that a two-sided t test at level ``alpha``
    with ``dof`` degrees of freedom rejects with probability ``power`` (bisection)."""
    critical = t_critical(alpha, dof)
    lo, hi = 0.0, 100.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if t_power(mid, dof, critical) < power:
            lo = mid
        else:
            hi = mid
    return hi


def welch(hairis, cycles):
    """Welch's test of the means of two samples along axis 0: (difference, standard error,
    degrees of freedom), each of the remaining shape."""
    n_h, n_c = hairis.shape[0], cycles.shape[0]
    a = hairis.var(axis=0, ddof=1) / n_h
    b = cycles.var(axis=0, ddof=1) / n_c
    error = np.sqrt(a + b)
    dof = (a + b) ** 2 / np.maximum(a * a / (n_h - 1) + b * b / (n_c - 1), 1e-300)
    return hairis.mean(axis=0) - cycles.mean(axis=0), error, dof


def masked_means(images, mask):
    """(seeds, channels) means of a (seeds, height, width, 3) stack over the pixels ``mask``
    (height, width) marks."""
    return images[:, mask, :].mean(axis=1)


def hair_statistics(cycles, hairis, masks, alpha_means=0.005, alpha_blocks=0.005, power=0.9,
                    block=16, min_pixels=32):
    """The hair comparison's figures, asserting nothing.

    ``masks``: {name: (height, width) bool}, the first the hair as a whole. Per mask and
    channel: the relative difference of the masked means, its t (Welch), the critical |t| at
    ``alpha_means`` Šidák-corrected over masks × channels, and the smallest relative bias found
    with ``power`` at that level. Per ``block``×``block`` block of the first mask with at least
    ``min_pixels`` hair pixels: t of its hair mean, against a critical |t| at ``alpha_blocks``
    Šidák-corrected over blocks × channels. ``detected``: whether any mean or block is beyond
    its critical value.
    """
    tests = 3 * len(masks)
    alpha_mean = 1.0 - (1.0 - alpha_means) ** (1.0 / tests)
    groups = {}
    detected = False
    for name, mask in masks.items():
        reference = masked_means(cycles, mask)
        difference, error, dof = welch(masked_means(hairis, mask), reference)
        level = reference.mean(axis=0)
        t = difference / error
        critical = np.array([t_critical(alpha_mean, d) for d in dof])
        shift = np.array([detectable_shift(d, alpha_mean, power) for d in dof])
        groups[name] = {"pixels": int(mask.sum()), "relative": difference / level, "t": t,
                        "dof": dof, "critical": critical,
                        "detectable": shift * error / level}
        detected |= bool(np.any(np.abs(t) > critical))
    hair = next(iter(masks.values()))
    height, width = hair.shape
    block_t, block_dof = [], []
    for y in range(0, height - block + 1, block):
        for x in range(0, width - block + 1, block):
            inside = hair[y:y + block, x:x + block]
            if inside.sum() < min_pixels:
                continue
            window = (slice(None), slice(y, y + block), slice(x, x + block))
            difference, error, dof = welch(masked_means(hairis[window], inside),
                                           masked_means(cycles[window], inside))
            block_t.append(difference / error)
            block_dof.append(dof)
    block_t, block_dof = np.array(block_t), np.array(block_dof)
    alpha_block = 1.0 - (1.0 - alpha_blocks) ** (1.0 / max(block_t.size, 1))
    block_critical = np.array([t_critical(alpha_block, d) for d in block_dof.reshape(-1)])
    block_excess = np.abs(block_t.reshape(-1)) / block_critical
    detected |= bool(np.any(block_excess > 1.0))
    return {"groups": groups, "blocks": block_t.shape[0], "block_t": block_t,
            "block_excess": float(block_excess.max()), "detected": detected,
            "alpha_mean": alpha_mean}


def print_hair_statistics(figures, label):
    """Prints :func:`hair_statistics`' figures, one line per mask and one for the blocks."""
    for name, group in figures["groups"].items():
        print("%s: %s hair (%d pixels): relative difference %s, t %s (critical %s, dof %s); "
              "smallest bias found with 90%% power %s"
              % (label, name, group["pixels"], np.round(group["relative"], 4),
                 np.round(group["t"], 2), np.round(group["critical"], 2),
                 np.round(group["dof"], 1), np.round(group["detectable"], 4)))
    print("%s: %d blocks, max |t| %.2f, max |t|/critical %.2f; %s"
          % (label, figures["blocks"], float(np.abs(figures["block_t"]).max()),
             figures["block_excess"], "DIFFERENT" if figures["detected"] else "within the noise"))


def assert_hair(figures, largest_bias=0.01):
    """Asserts :func:`hair_statistics`' figures: the first mask's smallest detectable bias is at
    most ``largest_bias`` in every channel, and no mean or block differs beyond the noise."""
    hair = next(iter(figures["groups"].values()))
    assert np.all(hair["detectable"] <= largest_bias), \
        "too little power: the smallest bias found with 90%% power is %s > %g" \
        % (hair["detectable"], largest_bias)
    assert not figures["detected"], "the hair differs beyond the noise"

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

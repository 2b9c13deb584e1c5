"""Mesh stiffness methods: hand calculations, ISO 6336-1 values, published values.

No expected number below was taken from this code's own output: each comes from a
hand calculation written out beside it, from ISO 6336-1, or from a paper (cited).
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from torquesplit.errors import ModelError
from torquesplit.gears.geometry import GearGeometry, PairGeometry
from torquesplit.gears.stiffness import (
    MeshStiffness,
    basic_rack_factor,
    blank_factor,
    compare_methods,
    constant_stiffness,
    fit_load_deflection,
    fourier_stiffness,
    iso6336_mesh_stiffness_value,
    iso6336_stiffness,
    iso6336_values,
    load_fit_stiffness,
    load_table_stiffness,
    mesh_stiffness,
    minimum_flexibility,
    pair_compliance,
    potential_energy_stiffness,
    table_stiffness,
    tooth_compliance,
)
from torquesplit.gears.stiffness.phasing import contact_line_length, phase_grid

DEG = math.pi / 180.0
A20 = 20 * DEG
E_STEEL, NU = 206e9, 0.3


def spur(z1=20, z2=40, m=2e-3, b=20e-3, x1=0.0, x2=0.0):
    return PairGeometry(GearGeometry(z1, m, A20, face_width=b, profile_shift=x1),
                        GearGeometry(z2, m, A20, face_width=b, profile_shift=x2))


def helical(z1, z2, m, beta, b, double=False):
    return PairGeometry(GearGeometry(z1, m, A20, beta, b, double_helical=double),
                        GearGeometry(z2, m, A20, -beta, b, double_helical=double))


def double_fraction(k: MeshStiffness) -> float:
    """Fraction of the cycle in the upper (double-contact) level of a two-level waveform."""
    mid = 0.5 * (k.minimum + k.maximum)
    return float(np.mean(k.stiffness > mid))


# ---------------------------------------------------------------- ISO 6336-1 ---------

def test_iso_q_prime_of_a_profile_shifted_pair_against_hand_calculation():
    # spur, z1 = 17, z2 = 53 (zn = z), x1 = +0.3, x2 = -0.1; ISO 6336-1 method B:
    #   C1           =  0.04723
    #   C2/zn1       =  0.15551 / 17           =  0.0091476
    #   C3/zn2       =  0.25791 / 53           =  0.0048662
    #   C4 x1        = -0.00635 x 0.3          = -0.0019050
    #   C5 x1/zn1    = -0.11654 x 0.3 / 17     = -0.0020566
    #   C6 x2        = -0.00193 x (-0.1)       = +0.0001930
    #   C7 x2/zn2    = -0.24188 x (-0.1) / 53  = +0.0004564
    #   C8 x1^2      =  0.00529 x 0.09         = +0.0004761
    #   C9 x2^2      =  0.00182 x 0.01         = +0.0000182
    #   q' = 0.0584260 mm um/N  ->  c'_th = 1/q' = 17.1157 N/(mm um)
    p = spur(17, 53, x1=0.3, x2=-0.1)
    v = iso6336_values(p)
    assert v.q_prime_iso == pytest.approx(0.0584260, abs=2e-7)
    assert v.q_prime == pytest.approx(0.0584260e-9, rel=5e-6)           # SI, m^2/N
    assert v.c_prime_th == pytest.approx(17.1157e9, rel=2e-5)           # SI, N/m^2
    # c' = c'_th C_M C_R C_B cos(beta) = 17.1157 x 0.8 x 1 x 0.975 x 1 = 13.3502 N/(mm um)
    assert v.c_prime_iso == pytest.approx(13.3502, rel=2e-5)
    assert minimum_flexibility(17, 53, 0.3, -0.1) == pytest.approx(0.0584260e-9, rel=5e-6)


def test_iso_basic_rack_and_blank_factors():
    # C_B = [1 + 0.5 (1.2 - 1.25)] [1 - 0.02 (20 - 20)] = 0.975 for the ISO 53 rack
    assert basic_rack_factor(1.25, A20) == pytest.approx(0.975)
    # h_fP = 1.4 m_n, alpha = 25 deg: [1 + 0.5 (1.2 - 1.4)] [1 - 0.02 (20 - 25)] = 0.9 x 1.1 = 0.99
    assert basic_rack_factor(1.4, 25 * DEG) == pytest.approx(0.99)
    # C_R = 1 + ln(b_s/b) / (5 exp(s_R/(5 m_n))); solid (b_s = b): 1
    assert blank_factor(0.05, 0.05, 0.01, 0.004) == pytest.approx(1.0)
    # b_s/b = 0.5, s_R/m_n = 2.5: 1 + ln 0.5 / (5 e^0.5) = 1 - 0.693147 / 8.243606 = 0.915917
    assert blank_factor(0.04, 0.02, 0.01, 0.004) == pytest.approx(0.915917, abs=1e-6)


@pytest.mark.parametrize("z1,z2", [(17, 51), (18, 54), (20, 40), (22, 66), (25, 50)])
def test_iso_standard_spur_values_are_near_the_standards_14_and_20(z1, z2):
    # ISO 6336-1 gives c' ~ 14 N/(mm um) and c_gamma ~ 20 N/(mm um) for solid steel spur
    # gears with the standard basic rack (its simplified values, for the usual
    # eps_alpha ~ 1.6); method B stays within about 10 % of them for such pairs.
    p = spur(z1, z2)
    assert 1.6 < p.transverse_contact_ratio < 1.7
    v = iso6336_values(p)
    assert v.c_prime_iso == pytest.approx(14.0, rel=0.12)
    assert v.c_gamma_iso == pytest.approx(20.0, rel=0.12)
    assert v.c_prime == pytest.approx(v.c_prime_iso * 1e9)    # N/m per m of face width
    assert v.mesh_stiffness == pytest.approx(v.c_gamma * 20e-3)  # total, N/m


def test_iso_spur_waveform_single_and_double_zones():
    p = spur()
    v = iso6336_values(p)
    k = iso6336_stiffness(p, n=1000, scale="single_pair")
    # single contact: c' b, double contact: 2 c' b (scale 'single_pair')
    assert k.minimum == pytest.approx(v.c_prime * 20e-3, rel=1e-12)
    assert k.maximum == pytest.approx(2 * v.c_prime * 20e-3, rel=1e-12)
    assert double_fraction(k) == pytest.approx(p.transverse_contact_ratio - 1, abs=2e-3)
    # the cycle starts with a new pair entering: double contact at phase 0
    assert k.stiffness[0] == k.maximum
    scaled = iso6336_stiffness(p, n=1000, scale="c_gamma")
    assert scaled.mean == pytest.approx(v.mesh_stiffness, rel=1e-12)
    # the default is ISO's mean mesh stiffness for a spur pair as for a helical one: the
    # mean does not jump by 10 % between a helix angle of 0 and 0.01 deg
    assert np.array_equal(iso6336_stiffness(p, n=1000).stiffness, scaled.stiffness)
    near = helical(20, 40, 2e-3, 0.01 * DEG, 20e-3)
    assert iso6336_stiffness(near, n=1000).mean == pytest.approx(scaled.mean, rel=1e-4)
    assert iso6336_mesh_stiffness_value(p) == pytest.approx(v.c_gamma * 20e-3, rel=1e-12)


def test_contact_line_length_identities():
    # mean total contact-line length of one helix = eps_alpha b / cos(beta_b)
    h = helical(23, 71, 3e-3, 17 * DEG, 33e-3)
    L = contact_line_length(h, phase_grid(4000))
    assert L.mean() == pytest.approx(h.transverse_contact_ratio * 33e-3 / math.cos(h.base_helix_angle),
                                     rel=1e-3)
    # an integer overlap ratio makes it constant: b = pi m_n / sin(beta) gives eps_beta = 1
    b1 = math.pi * 3e-3 / math.sin(17 * DEG)
    h1 = helical(23, 71, 3e-3, 17 * DEG, b1)
    assert h1.overlap_contact_ratio == pytest.approx(1.0)
    L1 = contact_line_length(h1, phase_grid(500))
    assert np.ptp(L1) < 1e-9 * L1.mean()


def test_iso_helical_waveform_mean_is_c_gamma_along_the_normal():
    h = helical(23, 215, 3.965e-3, 30 * DEG, 50e-3, double=True)
    v = iso6336_values(h)
    k = iso6336_stiffness(h)
    assert k.info["scale"] == "c_gamma"
    # c_gamma b (transverse, ISO) / cos^2(beta_b) along the flank normal
    assert k.mean == pytest.approx(v.c_gamma * 0.1 / math.cos(h.base_helix_angle) ** 2, rel=1e-12)


def test_iso_other_material_and_low_line_load():
    p = spur()
    steel = iso6336_values(p)
    # grey cast iron on steel, E = 118 GPa: E = 2 x 206 x 118 / 324 = 150.049 GPa; ratio 0.728395
    mixed = iso6336_values(p, young_modulus=(206e9, 118e9))
    assert mixed.c_prime / steel.c_prime == pytest.approx(0.728395, rel=1e-6)
    # F_t K_A / b = 50 N/mm: factor (50/100)^0.25 = 0.840896
    low = iso6336_values(p, line_load=50e3)
    assert low.c_prime / steel.c_prime == pytest.approx(0.840896, rel=1e-6)


# ------------------------------------------------------- potential energy ---------

def tian_compliances(z, m, alpha, u_c, E, nu):
    """Tian (2004) bending/shear/axial compliances per unit width, integrated in
    the tangent-point angle alpha from -alpha_1 to alpha_2 (tooth from the base circle):

    1/k_b = int 3{1 + cos a1[(a2 - a) sin a - cos a]}^2 (a2 - a) cos a / (2 E [sin a + (a2 - a) cos a]^3) da
    1/k_s = int 1.2 (1 + nu) (a2 - a) cos a cos^2 a1 / (E [sin a + (a2 - a) cos a]) da
    1/k_a = int (a2 - a) cos a sin^2 a1 / (2 E [sin a + (a2 - a) cos a]) da
    with a2 = pi/(2z) + inv(alpha), a1 = u_c - a2.
    """
    a2 = math.pi / (2 * z) + math.tan(alpha) - alpha
    a1 = u_c - a2

    def den(a):
        return math.sin(a) + (a2 - a) * math.cos(a)

    kb = quad(lambda a: 3 * (1 + math.cos(a1) * ((a2 - a) * math.sin(a) - math.cos(a))) ** 2
              * (a2 - a) * math.cos(a) / (2 * E * den(a) ** 3), -a1, a2, epsabs=0, epsrel=1e-11)[0]
    ks = quad(lambda a: 1.2 * (1 + nu) * (a2 - a) * math.cos(a) * math.cos(a1) ** 2 / (E * den(a)),
              -a1, a2, epsabs=0, epsrel=1e-11)[0]
    ka = quad(lambda a: (a2 - a) * math.cos(a) * math.sin(a1) ** 2 / (2 * E * den(a)),
              -a1, a2, epsabs=0, epsrel=1e-11)[0]
    return kb, ks, ka


def test_potential_energy_tooth_terms_match_tian_2004_integrals():
    # a tooth whose root circle is its base circle (Tian's assumption):
    # h_f = z (1 - cos alpha) / 2 = 20 x 0.0603074 / 2 = 0.603074 modules
    z, m = 20, 2e-3
    g = GearGeometry(z, m, A20, face_width=20e-3, dedendum=z * (1 - math.cos(A20)) / 2)
    assert g.root_radius == pytest.approx(g.base_radius, rel=1e-12)
    rolls = np.array([0.25, 0.36, 0.45, 0.55])  # tan of the pressure angle at the contact point
    c = tooth_compliance(g, rolls, young_modulus=E_STEEL, poisson_ratio=NU, fillet_foundation=False)
    for i, u in enumerate(rolls):
        kb, ks, ka = tian_compliances(z, m, A20, u, E_STEEL, NU)
        assert c.bending[i] == pytest.approx(kb, rel=1e-6)
        assert c.shear[i] == pytest.approx(ks, rel=1e-6)
        assert c.axial[i] == pytest.approx(ka, rel=1e-6)
    assert np.all(c.fillet == 0)


def test_hertz_term_is_yang_and_lin():
    # k_h = pi E b / (4 (1 - nu^2)); per unit width compliance 4 (1 - 0.09) / (pi 206e9)
    p = spur()
    d = pair_compliance(p, np.array([0.0]), young_modulus=E_STEEL, poisson_ratio=NU)
    assert d["hertz"] == pytest.approx(4 * 0.91 / (math.pi * 206e9), rel=1e-12)


def test_potential_energy_spur_zones_match_the_contact_ratio():
    p = spur()
    n = 256
    k = potential_energy_stiffness(p, n)
    # slicing a spur pair changes nothing (all slices in phase)
    assert np.array_equal(potential_energy_stiffness(p, n, slices=40).stiffness, k.stiffness)
    frac = double_fraction(k)
    assert abs(frac - (p.transverse_contact_ratio - 1)) <= 2 / n
    assert k.stiffness[0] > 0.5 * (k.minimum + k.maximum)  # phase 0: a pair enters


def test_potential_energy_spur_mean_within_30_percent_of_iso():
    for pair in (spur(), spur(25, 75, m=3e-3, b=30e-3), spur(30, 45)):
        k = potential_energy_stiffness(pair)
        iso = iso6336_values(pair).mesh_stiffness
        assert k.mean == pytest.approx(iso, rel=0.30)


def test_fillet_foundation_lowers_the_stiffness():
    p = spur()
    with_f = potential_energy_stiffness(p, fillet_foundation=True)
    without = potential_energy_stiffness(p, fillet_foundation=False)
    assert np.all(with_f.stiffness < without.stiffness)
    # a smaller bore (more gear body, larger h_fi = r_f / r_int) is more compliant (Sainsot 2004)
    r_f1, r_f2 = p.gear1.root_radius, p.gear2.root_radius
    big_bore = potential_energy_stiffness(p, bore_radius=(0.6 * r_f1, 0.6 * r_f2))
    small_bore = potential_energy_stiffness(p, bore_radius=(0.3 * r_f1, 0.3 * r_f2))
    assert small_bore.mean < big_bore.mean


def test_helical_slices_converge_and_double_helical_is_two_helices():
    h = helical(24, 51, 4e-3, 18 * DEG, 110e-3)
    k50 = potential_energy_stiffness(h, 128, slices=50)
    k200 = potential_energy_stiffness(h, 128, slices=200)
    assert k50.mean == pytest.approx(k200.mean, rel=1e-3)
    dh = helical(24, 51, 4e-3, 18 * DEG, 110e-3, double=True)
    kdh = potential_energy_stiffness(dh, 128, slices=50)
    assert np.allclose(kdh.stiffness, 2 * k50.stiffness, rtol=1e-12)
    # a stagger of half a cycle shifts the second helix: same mean, different waveform
    kst = potential_energy_stiffness(dh, 128, slices=50, stagger=0.5)
    assert kst.mean == pytest.approx(kdh.mean, rel=1e-3)
    assert kst.peak_to_peak < kdh.peak_to_peak


def test_helical_integer_overlap_ratio_gives_nearly_constant_stiffness():
    # with eps_beta = 1 the slices of all pairs cover the path of contact uniformly
    b1 = math.pi * 3e-3 / math.sin(17 * DEG)
    h = helical(23, 71, 3e-3, 17 * DEG, b1)
    k = potential_energy_stiffness(h, 128, slices=100)
    assert k.fluctuation < 0.02


def test_potential_energy_refuses_ring_gears():
    ring = PairGeometry(GearGeometry(20, 2e-3, A20, face_width=0.02),
                        GearGeometry(80, 2e-3, A20, face_width=0.02, internal=True))
    with pytest.raises(ModelError, match="iso6336"):
        potential_energy_stiffness(ring)
    assert iso6336_stiffness(ring).mean > 0


# ---------------------------------------------------------- tables, fits ---------

def test_table_is_resampled_periodically():
    # samples out of order, with a duplicate end point at 1.0
    k = table_stiffness([0.5, 0.0, 1.0, 0.25], [3e8, 1e8, 1e8, 2e8], n=8)
    # hand: linear 0 -> 0.25 -> 0.5 then back to 1e8 at phase 1
    expected = [1e8, 1.5e8, 2e8, 2.5e8, 3e8, 2.5e8, 2e8, 1.5e8]
    assert np.allclose(k.stiffness, expected)
    assert k.mean == pytest.approx(2e8) and k.peak_to_peak == pytest.approx(2e8)
    # wrap-around: a table that does not start at 0
    w = table_stiffness([0.25, 0.75], [1e8, 3e8], n=4)
    assert np.allclose(w.stiffness, [2e8, 1e8, 2e8, 3e8])


def test_fourier_series():
    k = fourier_stiffness(5e8, cos=[1e8, 0.0], sin=[0.0, 2e7], n=64)
    phi = np.arange(64) / 64
    assert np.allclose(k.stiffness, 5e8 + 1e8 * np.cos(2 * np.pi * phi) + 2e7 * np.sin(4 * np.pi * phi))
    mean, a, b = k.fourier(3)
    assert mean == pytest.approx(5e8)
    assert a == pytest.approx([1e8, 0, 0], abs=1e-3)
    assert b == pytest.approx([0, 2e7, 0], abs=1e-3)
    with pytest.raises(ModelError, match="negative"):
        fourier_stiffness(1e8, cos=[2e8])


def test_load_tables_are_interpolated_in_load():
    phase = [0.0, 0.5]
    k = load_table_stiffness([1000.0, 3000.0], phase, [[1e8, 2e8], [3e8, 4e8]], load=1500.0, n=2)
    # a quarter of the way from the first to the second table
    assert np.allclose(k.stiffness, [1.5e8, 2.5e8])
    with pytest.raises(ModelError, match="outside"):
        load_table_stiffness([1000.0, 3000.0], phase, [[1e8, 2e8], [3e8, 4e8]], load=5000.0)


def test_seed002_load_fit_recovers_coefficients_and_gives_eq18_stiffness():
    # seed 002 eq. 17: dphi = a + b T + c T^(2/3), at 0.1, 0.5, 0.9 of T = 2000 N m
    a, b, c = 2e-5, 3e-8, 1e-7
    T = np.array([200.0, 1000.0, 1800.0])
    d = a + b * T + c * T ** (2 / 3)
    fit = fit_load_deflection(T, d)
    assert (float(fit.a), float(fit.b), float(fit.c)) == pytest.approx((a, b, c), rel=1e-8)
    # eq. 18 by hand at T = 1000 N m, r_b = 0.05 m, alpha_n = 20 deg, beta = 0:
    #   dphi = 2e-5 + 3e-5 + 1e-7 x 100 = 6.0e-5 rad   (1000^(2/3) = 100)
    #   k = 1000 / (0.0025 x cos 20) / 6.0e-5 = 1000 / 0.00234923 / 6e-5 = 7.094517e9 N/m
    assert float(fit.stiffness(1000.0, 0.05, A20)) == pytest.approx(7.094517e9, rel=1e-6)
    # negative torque: odd-symmetric deflection, same stiffness
    assert float(fit.stiffness(-1000.0, 0.05, A20)) == pytest.approx(7.094517e9, rel=1e-6)
    # one fit per mesh position -> a waveform
    dd = np.outer(d, [1.0, 1.1, 1.2, 1.1])
    wave = load_fit_stiffness(fit_load_deflection(T, dd), 1000.0, 0.05, A20, n=8)
    assert wave.stiffness[0] == pytest.approx(7.094517e9, rel=1e-6)
    assert wave.stiffness[4] == pytest.approx(7.094517e9 / 1.2, rel=1e-6)


# ------------------------------------------------------- dispatch, result ---------

def test_dispatcher_and_unknown_options():
    p = spur()
    assert mesh_stiffness(p, "iso6336").method == "iso6336"
    assert mesh_stiffness(p, "potential_energy", n=64).n == 64
    assert mesh_stiffness(None, "constant", mean=3e8).peak_to_peak == 0.0
    assert mesh_stiffness(None, "fourier", mean=3e8, cos=[1e7]).method == "fourier"
    with pytest.raises(TypeError, match="fillet"):
        mesh_stiffness(p, "potential_energy", filet_foundation=False)  # misspelt option
    with pytest.raises(ModelError, match="choose one of"):
        mesh_stiffness(p, "fem")
    with pytest.raises(ModelError, match="needs the pair"):
        mesh_stiffness(None, "iso6336")


def test_mesh_stiffness_result_behaviour():
    k = table_stiffness([0.0, 0.5], [1e8, 3e8], n=4)
    assert float(k(0.25)) == pytest.approx(2e8)
    assert float(k(1.25)) == pytest.approx(2e8)  # periodic
    with pytest.raises(ValueError):
        k.stiffness[0] = 0.0  # read-only
    assert k.resample(8).mean == pytest.approx(2e8)
    with pytest.raises(ModelError, match="negative"):
        MeshStiffness.from_samples([1.0, -1.0], "x")
    assert constant_stiffness(2e8, 16).fluctuation == 0.0


def test_compare_methods_and_plot(tmp_path):
    c = compare_methods(spur(), n=128)
    labels = [r["method"] for r in c.rows()]
    assert labels[:2] == ["iso6336 (c_gamma)", "iso6336 (single_pair)"] and "potential_energy" in labels
    assert c.results[0].mean == pytest.approx(c.iso_mesh_stiffness)
    assert c.iso_mesh_stiffness == pytest.approx(iso6336_values(spur()).mesh_stiffness)
    assert "c_gamma" in c.table()
    from torquesplit.plot.mesh import plot_mesh_stiffness
    out = plot_mesh_stiffness(c, tmp_path / "mesh.png")
    assert out.exists() and out.stat().st_size > 1000

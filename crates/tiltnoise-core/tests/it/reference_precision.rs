//! The double-double reference evaluator (`tiltnoise_core::reference`) against 50-digit mpmath, the
//! 40-digit mpmath fixture of the ROMY budget, the exact quasi-static limits, and the f64 direct
//! method.
//!
//! Run with `cargo test --release -p tiltnoise-core --test it reference_precision -- --nocapture`
//! to see the measured agreement, the direct method's error per entry over 1e-5..100 Hz (the
//! accuracy column of the methods table of `tiltnoise methods`) and the time per reference evaluation.
//!
//! # Tolerances
//!
//! One double-double operation errs by at most `DD_EPS = 2^-104 ~ 4.9e-32` relative. Every datum
//! of the model (an entry of K, M, G0, G2, B or C) is built from the exact parameter values by
//! at most about a dozen such operations, and the reference's solve (LU with partial pivoting
//! plus one step of iterative refinement) is componentwise backward stable. So the error of an
//! entry is bounded by a small multiple of `DD_EPS kappa`, where `kappa` is the entry's
//! componentwise condition number ([`ReferenceModel::entry_condition`]): [`DD_REF_FACTOR`]
//! below. `kappa` is 1..1e3 for most entries (about 3e3 at the ROMY bin closest to a mode, so
//! ~1e-28 there), up to 1e16 exactly on a resonance (rounded to f64, detuning ~1e-16) and large
//! where an entry is the small remainder of a cancellation inside the model (phi/eta_t ~ f^4 at
//! low frequency: kappa ~ 5e5 at 1 mHz; eta/phi_t at 100 Hz: 2e10).

use crate::common;
use crate::tolerances::{DD_REF_FACTOR, DIRECT_TOL_FACTOR};

use common::{floats, json};
use num_complex::Complex64;
use tiltnoise_core::error::{FreqError, TfError};
use tiltnoise_core::model::{ForceInput, Model, Observable, TiltAxis};
use tiltnoise_core::params::Params;
use tiltnoise_core::reference::{relative_errors, CDd, Dd, ReferenceModel, DD_EPS};
use tiltnoise_core::tf::{plan, Input, Method, Request};

/// mpmath reference values `(freq_hz, output index in crate order (X, Y, Z, theta, eta, phi,
/// phi_a), input, [re_hi, re_lo, im_hi, im_lo])`, each part `hi + lo` with `hi = float(x)`,
/// `lo = float(x - hi)`; input "T<j>" is tilt axis j, "F<k>" force component k. Every nonzero
/// entry of the 7 x (3 or 5) matrix is listed. Generated with mpmath 1.3.0 at 50 digits by the
/// independent model of `scripts/reference/tilt_budget_reference.py` (run from the repository
/// root):
///
/// ```python
/// import sys; sys.path.insert(0, "scripts/reference")
/// import tilt_budget_reference as t
/// mp = t.mp
/// mp.mp.dps = 50
/// tp = t.load_params()
/// m = t.build_model(tp)
/// C = mp.matrix(7, 8)  # rows X, Y, Z, theta, eta, phi, phi_a (crate order)
/// for c in range(8):
///     C[0, c] = m["C"][0, c]; C[5, c] = m["C"][1, c]; C[6, c] = m["C"][2, c]
///     for r in range(4): C[1 + r, c] = m["C_extra"][r, c]
/// def dd(x):
///     hi = float(x); return (hi, float(x - hi))
/// def rows(model, f, cols):
///     w2 = (2 * mp.pi * mp.mpf(f)) ** 2
///     A = model["Kg"] + model["Ke"] - w2 * model["M"]
///     out = []
///     for name, rhs in cols:
///         q = mp.lu_solve(A, rhs(w2))
///         y = C * q
///         for o in range(7):
///             z = mp.mpc(y[o])
///             if z != 0:
///                 out.append((f, o, name) + dd(z.real) + dd(z.imag))
///     return out
/// tilt = [(j, (lambda w2, j=j: m["G0"].column(j) + w2 * m["G2"].column(j))) for j in range(3)]
/// lines = []
/// for f in (1e-3, 0.0013102308550540422, 0.0048828125, 0.41491272636188614, 0.4150390625,
///           0.6, 3.0, 100.0):
///     lines += rows(m, f, [("T%d" % j, r) for j, r in tilt])
/// tp2 = dict(tp); tp2["loss"] = dict(tp["loss"])
/// tp2["loss"]["torsion_a_rad"] = 1e-3; tp2["loss"]["torsion_b_rad"] = 1e-3
/// m2 = t.build_model(tp2)
/// force = [("F%d" % k, (lambda w2, k=k: m2["B"].column(k))) for k in (11, 3)]
/// tilt2 = [("T%d" % j, (lambda w2, j=j: m2["G0"].column(j) + w2 * m2["G2"].column(j)))
///          for j in range(3)]
/// damped = []
/// for f in (1.31e-3, 0.4150390625, 10.0):
///     damped += rows(m2, f, tilt2 + force)
/// def emit(name, ls):
///     print("const %s: &[Hp] = &[" % name)
///     for (f, o, i, rh, rl, ih, il) in ls:
///         print("    (%r, %d, %s, [%r, %r, %r, %r])," % (f, o, '"%s"' % i, rh, rl, ih, il))
///     print("];")
/// emit("MP_UNDAMPED", lines)
/// emit("MP_DAMPED", damped)
/// ```
///
/// 0.0013102308550540422 and 0.41491272636188614 Hz are two undamped modes (the fixture's
/// `checks.mode_frequencies_hz`) rounded to f64; 0.4150390625 Hz is the ROMY bin closest to a
/// mode. MP_DAMPED has loss angles 1e-3 on both torsion fibres and the inputs theta_t, eta_t,
/// phi_t, M_b.z, F_b.x.
type Hp = (f64, usize, &'static str, [f64; 4]);

#[rustfmt::skip]
const MP_UNDAMPED: &[Hp] = &[
    (0.001, 1, "T0", [1.6640133975395897, -2.656013629622449e-17, 0.0, 0.0]),
    (0.001, 2, "T0", [-0.1500012077104478, 6.111247796961103e-18, 0.0, 0.0]),
    (0.001, 3, "T0", [1.000008051409438, -1.0257037883684772e-16, 0.0, 0.0]),
    (0.001, 0, "T1", [-1.66401425834046, -8.139906837758325e-17, 0.0, 0.0]),
    (0.001, 4, "T1", [1.0000080514129037, -8.014293775318939e-17, 0.0, 0.0]),
    (0.001, 5, "T1", [-7.230152367779037e-06, -2.419959741885855e-22, 0.0, 0.0]),
    (0.001, 6, "T1", [-5.738654120648126e-06, 2.195037294214864e-22, 0.0, 0.0]),
    (0.001, 0, "T2", [-0.2090903614943293, 2.898992800014073e-18, 0.0, 0.0]),
    (0.001, 4, "T2", [1.4455820792533716e-06, -8.40371532912412e-23, 0.0, 0.0]),
    (0.001, 5, "T2", [-2.016119152926731, 2.1105054234246817e-16, 0.0, 0.0]),
    (0.001, 6, "T2", [-1.3939280564049226, 4.396342314395433e-17, 0.0, 0.0]),
    (0.0013102308550540422, 1, "T0", [1.6640229997231284, 1.0131454366547823e-16, 0.0, 0.0]),
    (0.0013102308550540422, 2, "T0", [-0.15000207329101517, -3.0828061780915894e-18, 0.0, 0.0]),
    (0.0013102308550540422, 3, "T0", [1.0000138219591175, -1.6333696313685458e-18, 0.0, 0.0]),
    (0.0013102308550540422, 0, "T1", [42379922027.792984, 2.9313031006939665e-06, 0.0, 0.0]),
    (0.0013102308550540422, 4, "T1", [-292882.4067382337, 1.7229019662733715e-11, 0.0, 0.0]),
    (0.0013102308550540422, 5, "T1", [437447457553.1405, 2.076302660829772e-05, 0.0, 0.0]),
    (0.0013102308550540422, 6, "T1", [282531256120.3695, 6.689039438353678e-06, 0.0, 0.0]),
    (0.0013102308550540422, 0, "T2", [5998848316227580.0, -0.023080494694240415, 0.0, 0.0]),
    (0.0013102308550540422, 4, "T2", [-41457441338.00799, 2.109945130928395e-06, 0.0, 0.0]),
    (0.0013102308550540422, 5, "T2", [6.19203815985481e+16, -3.4882663869098525, 0.0, 0.0]),
    (0.0013102308550540422, 6, "T2", [3.999210165798073e+16, 3.3048134595870677, 0.0, 0.0]),
    (0.0048828125, 1, "T0", [1.6643194671027763, 9.405215269321962e-17, 0.0, 0.0]),
    (0.0048828125, 2, "T0", [-0.15002879785885517, -1.3603740699663053e-17, 0.0, 0.0]),
    (0.0048828125, 3, "T0", [1.0001919893942834, -3.774664394138654e-17, 0.0, 0.0]),
    (0.0048828125, 0, "T1", [-1.6643035613047894, -1.0453212088659513e-16, 0.0, 0.0]),
    (0.0048828125, 4, "T1", [1.0001919878678753, 8.364841524108486e-17, 0.0, 0.0]),
    (0.0048828125, 5, "T1", [-2.7060300536678648e-05, 8.127865831717221e-23, 0.0, 0.0]),
    (0.0048828125, 6, "T1", [0.00010603049120825899, -4.199202710478096e-21, 0.0, 0.0]),
    (0.0048828125, 0, "T2", [0.16167109281608089, -7.598605640929366e-18, 0.0, 0.0]),
    (0.0048828125, 4, "T2", [-1.1201840904956654e-06, -5.434638686241094e-23, 0.0, 0.0]),
    (0.0048828125, 5, "T2", [0.9801441329164827, -2.6848731081303894e-17, 0.0, 0.0]),
    (0.0048828125, 6, "T2", [1.0778013288277266, -7.635783807954943e-17, 0.0, 0.0]),
    (0.41491272636188614, 1, "T0", [3.736125379133524e+16, -3.98776495142038, 0.0, 0.0]),
    (0.41491272636188614, 2, "T0", [-2978264673749121.0, -0.062386069558035634, 0.0, 0.0]),
    (0.41491272636188614, 3, "T0", [2.535311298262041e+16, 0.16723634516049724, 0.0, 0.0]),
    (0.41491272636188614, 0, "T1", [-560.0650508604909, -5.0334377205279645e-15, 0.0, 0.0]),
    (0.41491272636188614, 4, "T1", [381.28773247493956, 2.3742406936813432e-14, 0.0, 0.0]),
    (0.41491272636188614, 5, "T1", [-0.005427841312554355, -1.4862964822022395e-19, 0.0, 0.0]),
    (0.41491272636188614, 6, "T1", [192.75414338422055, -2.395244620282505e-16, 0.0, 0.0]),
    (0.41491272636188614, 0, "T2", [0.1500274994555482, -1.2853924744111671e-17, 0.0, 0.0]),
    (0.41491272636188614, 4, "T2", [-1.8661109893809977e-05, -1.3960210713255589e-21, 0.0, 0.0]),
    (0.41491272636188614, 5, "T2", [0.9999999999831498, 8.039393866384654e-18, 0.0, 0.0]),
    (0.41491272636188614, 6, "T2", [1.0000005983855829, -6.418146964018444e-17, 0.0, 0.0]),
    (0.4150390625, 1, "T0", [-4222.516953306509, 2.1807855624393876e-13, 0.0, 0.0]),
    (0.4150390625, 2, "T0", [336.53425009769364, -1.3625003255680645e-14, 0.0, 0.0]),
    (0.4150390625, 3, "T0", [-2865.854267110434, -4.523427331442566e-14, 0.0, 0.0]),
    (0.4150390625, 0, "T1", [-655.0498421073153, 5.391543706213556e-14, 0.0, 0.0]),
    (0.4150390625, 4, "T1", [446.0095766443515, -1.0792603386617916e-14, 0.0, 0.0]),
    (0.4150390625, 5, "T1", [-0.006347684693292768, 4.553806759140346e-20, 0.0, 0.0]),
    (0.4150390625, 6, "T1", [225.55703061646352, 5.528954810498758e-15, 0.0, 0.0]),
    (0.4150390625, 0, "T2", [0.15003170285336415, 8.332499734157471e-19, 0.0, 0.0]),
    (0.4150390625, 4, "T2", [-2.152636271274435e-05, 6.957301653446437e-22, 0.0, 0.0]),
    (0.4150390625, 5, "T2", [1.0000000000241984, -5.282011120240888e-17, 0.0, 0.0]),
    (0.4150390625, 6, "T2", [0.9999991401412726, 1.1078975381423701e-17, 0.0, 0.0]),
    (0.6, 1, "T0", [19.11831276573207, 1.3835449778315869e-17, 0.0, 0.0]),
    (0.6, 2, "T0", [0.5394967430098834, -4.291716618164311e-17, 0.0, 0.0]),
    (0.6, 3, "T0", [27.99313255790117, 1.5398978698297445e-15, 0.0, 0.0]),
    (0.6, 0, "T1", [7.042329831084762, 4.134657730293122e-16, 0.0, 0.0]),
    (0.6, 4, "T1", [-8.305281395299943, 6.056779134851206e-16, 0.0, 0.0]),
    (0.6, 5, "T1", [6.0493866514504184e-05, -2.4076189043616986e-22, 0.0, 0.0]),
    (0.6, 6, "T1", [-4.492450432657328, 3.2132257252016357e-16, 0.0, 0.0]),
    (0.6, 0, "T2", [0.15000991576366218, -9.152439569582075e-18, 0.0, 0.0]),
    (0.6, 4, "T2", [-1.3758489881930229e-05, 2.219869511919956e-22, 0.0, 0.0]),
    (0.6, 5, "T2", [1.0000000000228562, -2.178591886402092e-18, 0.0, 0.0]),
    (0.6, 6, "T2", [0.999998302635154, 3.401083436014607e-17, 0.0, 0.0]),
    (3.0, 1, "T0", [-0.3953180847532917, 2.4240149470188916e-17, 0.0, 0.0]),
    (3.0, 2, "T0", [0.09842124043263498, 6.2353964297924535e-18, 0.0, 0.0]),
    (3.0, 3, "T0", [-0.017477544107186237, -3.980846116717318e-19, 0.0, 0.0]),
    (3.0, 0, "T1", [0.4026102107754509, -1.7318427266422353e-17, 0.0, 0.0]),
    (3.0, 4, "T1", [-0.14279317417457502, -6.984652490258433e-18, 0.0, 0.0]),
    (3.0, 5, "T1", [3.214462361390841e-07, 1.100262613454349e-23, 0.0, 0.0]),
    (3.0, 6, "T1", [-0.5967960197987712, -2.902550816606644e-17, 0.0, 0.0]),
    (3.0, 0, "T2", [0.149999997383166, -1.0231440016305538e-17, 0.0, 0.0]),
    (3.0, 4, "T2", [4.489551991271153e-08, -2.2078658087538173e-24, 0.0, 0.0]),
    (3.0, 5, "T2", [0.9999999999998856, -2.2478658345922424e-17, 0.0, 0.0]),
    (3.0, 6, "T2", [1.000000212349083, -1.0557794733277408e-16, 0.0, 0.0]),
    (100.0, 1, "T0", [-0.36705861320732885, 2.3804268901272785e-17, 0.0, 0.0]),
    (100.0, 2, "T0", [-0.15161076834075246, 1.2161954082289628e-17, 0.0, 0.0]),
    (100.0, 3, "T0", [-0.010910511969371517, -1.656323668392402e-19, 0.0, 0.0]),
    (100.0, 0, "T1", [0.37078100746008846, -1.4284285493283772e-18, 0.0, 0.0]),
    (100.0, 4, "T1", [-0.13250969682243588, -9.724901253817453e-18, 0.0, 0.0]),
    (100.0, 5, "T1", [2.864082061662708e-10, -5.76715997008451e-27, 0.0, 0.0]),
    (100.0, 6, "T1", [-0.5908275725384812, 2.6330979004093485e-17, 0.0, 0.0]),
    (100.0, 0, "T2", [0.14999999999881147, 1.2401243631430189e-17, 0.0, 0.0]),
    (100.0, 4, "T2", [3.8699226425229e-11, -3.157109656135737e-27, 0.0, 0.0]),
    (100.0, 5, "T2", [1.0, -9.225403950591731e-20, 0.0, 0.0]),
    (100.0, 6, "T2", [1.0000000001903095, 5.083873894081693e-17, 0.0, 0.0]),
];
#[rustfmt::skip]
const MP_DAMPED: &[Hp] = &[
    (0.00131, 1, "T0", [1.6640229916189222, -1.9641040353757907e-17, 0.0, 0.0]),
    (0.00131, 2, "T0", [-0.15000207256046866, -1.0940138375756435e-17, 0.0, 0.0]),
    (0.00131, 3, "T0", [1.000013817088794, 4.8646558192589284e-17, 0.0, 0.0]),
    (0.00131, 0, "T1", [-1.6643545229957604, -8.038467555596767e-17, 0.0009408894254412506, 3.374674297476964e-20]),
    (0.00131, 4, "T1", [1.0000138193791681, -1.574647883011951e-17, -6.500101644958393e-09, -1.4505346665832967e-25]),
    (0.00131, 5, "T1", [-0.0034160965905450404, -2.096452743781561e-19, 0.009711893649994389, 3.146596610353583e-19]),
    (0.00131, 6, "T1", [-0.0022101970000782114, -2.0970671497265631e-19, 0.006272561605277264, -1.6112284189691347e-19]),
    (0.00131, 0, "T2", [-46.94439916311975, -2.2410964604056275e-15, 133.22918447395506, 8.169082962409245e-17]),
    (0.00131, 4, "T2", [0.00032535000733477365, 2.6901802907376034e-20, -0.0009204091551453981, -9.852008869830553e-21]),
    (0.00131, 5, "T2", [-484.26270779672006, 7.834091909757859e-16, 1375.1971623292336, 7.083483307746226e-14]),
    (0.00131, 6, "T2", [-312.96093103677003, -3.8527656285991066e-15, 888.1896688782724, -5.4102606654155934e-14]),
    (0.00131, 0, "F11", [40324141.09658524, 1.0221590813491636e-09, -114640719.15920858, -6.076628664709342e-09]),
    (0.00131, 4, "F11", [-278.5779165819888, 2.5915611764392917e-14, 791.9913935014396, 5.558736122132435e-14]),
    (0.00131, 5, "F11", [633528412.4474362, 2.526576866325573e-08, -1183662638.5592537, -2.4079454688955836e-08]),
    (0.00131, 6, "F11", [268826125.97075784, -6.020498582349874e-09, -764267249.6422117, -4.8464432799492987e-08]),
    (0.00131, 0, "F3", [3913448.346128648, 7.360802567077288e-11, -11106404.058074372, -2.7866282225140706e-10]),
    (0.00131, 4, "F3", [-27.962935389675412, 4.1896196845875147e-16, 76.72820348002682, 2.976180651004811e-15]),
    (0.00131, 5, "F3", [40324131.624936074, -2.941655874931289e-10, -114640692.2315012, -1.1235960478648462e-09]),
    (0.00131, 6, "F3", [26089506.65940415, -5.14979803039097e-11, -74042285.71779484, -7.213277669466611e-09]),
    (0.4150390625, 1, "T0", [-4222.516953306509, 2.1807855624393876e-13, 0.0, 0.0]),
    (0.4150390625, 2, "T0", [336.53425009769364, -1.3625003255680645e-14, 0.0, 0.0]),
    (0.4150390625, 3, "T0", [-2865.854267110434, -4.523427331442566e-14, 0.0, 0.0]),
    (0.4150390625, 0, "T1", [-655.0498421073152, -5.436794052010756e-14, 7.179008993586899e-06, -2.475264914506187e-22]),
    (0.4150390625, 4, "T1", [446.0095766443515, -1.4461574173819073e-14, -4.874575475554722e-06, 1.9133347271206362e-22]),
    (0.4150390625, 5, "T1", [-0.006347684693119604, -9.09477223495103e-20, -6.347857851845899e-06, 2.6969841560266985e-22]),
    (0.4150390625, 6, "T1", [225.55703061646352, 5.382399788911343e-15, -1.9471223824989234e-07, -9.665613675976881e-24]),
    (0.4150390625, 0, "T2", [0.15003170285336417, 4.451604182250748e-19, 3.1702825996645856e-08, 3.1151521047952492e-24]),
    (0.4150390625, 4, "T2", [-2.152636271276293e-05, -1.4207205455619663e-21, -2.1526344130099183e-08, 1.6778165954909572e-25]),
    (0.4150390625, 5, "T2", [1.0000000000241984, -7.701979966066948e-17, 4.8397396556101906e-14, -1.1651261044298453e-30]),
    (0.4150390625, 6, "T2", [0.9999991401412726, 1.033670239209315e-17, -8.598579851575817e-10, -7.217595663082941e-27]),
    (0.4150390625, 0, "F11", [0.0004956610861904457, 5.009139038676706e-20, 4.956746073476091e-07, -3.3749961547479884e-23]),
    (0.4150390625, 4, "F11", [-0.0003365558362009476, 1.886585790024861e-21, -3.365650171200923e-07, 1.0497155965219376e-23]),
    (0.4150390625, 5, "F11", [-3963.6986495313713, -1.7357280537990524e-13, -0.00011154743883184473, -3.273330158671096e-21]),
    (0.4150390625, 6, "F11", [-1.3443537902199214e-05, 6.56772099217178e-22, -1.3443904628968512e-08, 3.894732953352641e-26]),
    (0.4150390625, 0, "F3", [46.379421792282606, 3.5251459086213603e-15, -5.476338055279514e-07, -2.717088396721601e-23]),
    (0.4150390625, 4, "F3", [-32.39950983110955, -3.1722724358232214e-15, 3.718455180089534e-07, 2.3776214950402017e-23]),
    (0.4150390625, 5, "F3", [0.00048421818775961354, 1.886741877225625e-20, 4.842313967655258e-07, 3.8523839191962427e-23]),
    (0.4150390625, 6, "F3", [-17.206087239955117, 1.537859778266417e-16, 1.485316484641662e-08, 5.798407234051969e-25]),
    (10.0, 1, "T0", [-0.36969329652165583, 1.7497213833568677e-17, 0.0, 0.0]),
    (10.0, 2, "T0", [0.017674634751264323, 1.2936842587728432e-18, 0.0, 0.0]),
    (10.0, 3, "T0", [-0.015389938899893128, 7.062173345978808e-19, 0.0, 0.0]),
    (10.0, 0, "T1", [0.37359733382933263, 4.990719612723178e-19, 7.650037856918948e-14, 3.5815262093515676e-31]),
    (10.0, 4, "T1", [-0.13345161005962092, -1.988623659408673e-18, -2.3062666531893666e-12, 1.6058607713623372e-28]),
    (10.0, 5, "T1", [2.866710562218742e-08, 1.3677554984135712e-25, 2.8667107559762333e-11, -2.7299867589810855e-28]),
    (10.0, 6, "T1", [-0.5913697739439315, 5.1857614337716496e-17, -1.1302820403754098e-11, 1.184848732407057e-28]),
    (10.0, 0, "T2", [0.14999999987114693, -5.8281724154378155e-18, -1.288530753960207e-13, -2.7089647065943e-31]),
    (10.0, 4, "T2", [3.8845499960261724e-09, -6.40605445298533e-26, 3.884550070271453e-12, 3.2377701632037276e-28]),
    (10.0, 5, "T2", [0.9999999999999991, -3.4695370237189844e-17, -1.8457494880001636e-18, 1.7041588316033215e-34]),
    (10.0, 6, "T2", [1.0000000190378553, 6.321179073679909e-17, 1.9037855719307174e-11, 7.707191359588114e-28]),
    (10.0, 0, "F11", [-3.4701400171769854e-12, -1.4066699830700428e-28, -3.470140251719542e-15, 1.1267073620780935e-31]),
    (10.0, 4, "F11", [1.0461475293583047e-10, -5.900558240594489e-27, 1.0461476000661477e-13, 5.05088931988697e-30]),
    (10.0, 5, "F11", [-6.827573352692739, 1.6769519716815094e-16, -3.3097188104314764e-10, 1.993724856970448e-26]),
    (10.0, 6, "F11", [5.127081737844946e-10, 5.273360806597798e-27, 5.127082084378184e-13, 1.93316632343041e-29]),
    (10.0, 0, "F3", [-0.0024031334660489165, -9.448236953034079e-20, 2.315299634637904e-19, -6.263526059749765e-36]),
    (10.0, 4, "F3", [0.003026147307622838, -7.73405752337543e-20, -6.97996328825683e-18, -6.629752694772188e-34]),
    (10.0, 5, "F3", [8.67615826412504e-14, -5.995807416639621e-30, 8.676158850536056e-17, -2.509581611683229e-34]),
    (10.0, 6, "F3", [-1.789792739796622e-06, -2.950894600316734e-23, -3.420821758093814e-17, 1.5958249989959822e-33]),
];

fn input_of(name: &str) -> Input {
    let k: usize = name[1..].parse().unwrap();
    match &name[..1] {
        "T" => Input::Tilt(TiltAxis::ALL[k]),
        _ => Input::Force(ForceInput::ALL[k]),
    }
}

/// Table I with loss angles 1e-3 on both torsion fibres (the MP_DAMPED case).
fn damped_params() -> Params {
    let mut p = Params::table_i();
    p.loss.torsion_a_rad = 1e-3;
    p.loss.torsion_b_rad = 1e-3;
    p
}

fn cdd(v: [f64; 4]) -> CDd {
    CDd::new(Dd { hi: v[0], lo: v[1] }, Dd { hi: v[2], lo: v[3] })
}

/// Relative error of a double-double value against another, in double-double.
fn rel_dd(got: CDd, want: CDd) -> f64 {
    ((got - want).norm_sqr() / want.norm_sqr()).sqrt().to_f64()
}

/// Distance in units in the last place between two f64 (0 for equal values, including 0 and
/// -0; `u64::MAX` for opposite signs).
fn ulps(a: f64, b: f64) -> u64 {
    if a == b {
        0
    } else if (a < 0.0) != (b < 0.0) {
        u64::MAX
    } else {
        a.abs().to_bits().abs_diff(b.abs().to_bits())
    }
}

fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| lo * (hi / lo).powf(k as f64 / (n - 1) as f64))
        .collect()
}

fn label(o: Observable, i: Input) -> String {
    format!("{}/{}", o.name(), i.name())
}

/// Test 1: double-double against 50-digit mpmath, entry by entry, within
/// `DD_REF_FACTOR DD_EPS kappa`; entries mpmath finds to be exactly zero are exactly zero.
#[test]
fn reference_matches_mpmath_within_its_condition() {
    let cases = [
        ("undamped", Params::table_i(), MP_UNDAMPED),
        ("damped", damped_params(), MP_DAMPED),
    ];
    for (name, params, table) in cases {
        let reference = ReferenceModel::new(&params);
        let mut inputs: Vec<&str> = table.iter().map(|e| e.2).collect();
        inputs.sort();
        inputs.dedup();
        let request = Request {
            outputs: Observable::ALL.to_vec(),
            inputs: inputs.iter().map(|s| input_of(s)).collect(),
        };
        let mut freqs: Vec<f64> = table.iter().map(|e| e.0).collect();
        freqs.dedup();
        let (mut worst, mut worst_ratio, mut worst_well) = (0.0f64, 0.0f64, 0.0f64);
        let mut checked = 0;
        for &f in &freqs {
            let h = reference.eval_dd(&request, f).unwrap();
            let kappa = reference.entry_condition(&request, f).unwrap();
            let mut worst_here = (0.0f64, String::new(), 0.0);
            for (o, &out) in request.outputs.iter().enumerate() {
                for (i, &inp) in request.inputs.iter().enumerate() {
                    let k = o * request.inputs.len() + i;
                    let want = table
                        .iter()
                        .find(|e| e.0 == f && e.1 == out.index() && input_of(e.2) == inp);
                    let Some(&(_, _, _, v)) = want else {
                        assert!(
                            h[k].is_zero(),
                            "{name} {f} Hz {}: {:?} is not exactly 0",
                            label(out, inp),
                            h[k]
                        );
                        continue;
                    };
                    let err = rel_dd(h[k], cdd(v));
                    let tol = DD_REF_FACTOR * DD_EPS * kappa[k].max(1.0);
                    assert!(
                        err <= tol,
                        "{name} {f} Hz {}: relative error {err:.2e} > {tol:.2e} (kappa {:.2e})",
                        label(out, inp),
                        kappa[k]
                    );
                    checked += 1;
                    worst = worst.max(err);
                    worst_ratio = worst_ratio.max(err / (DD_EPS * kappa[k].max(1.0)));
                    if kappa[k] <= 1e4 {
                        worst_well = worst_well.max(err);
                    }
                    if err > worst_here.0 {
                        worst_here = (err, label(out, inp), kappa[k]);
                    }
                }
            }
            println!(
                "mpmath {name:8} f = {f:<22} worst entry {:14} rel err {:.1e} (kappa {:.1e}), cond {:.1e}",
                worst_here.1,
                worst_here.0,
                worst_here.2,
                reference.condition_number(f).unwrap()
            );
        }
        println!(
            "mpmath {name}: {checked} nonzero entries; max rel err {worst:.1e}; max over kappa <= 1e4 \
             {worst_well:.1e}; max err / (DD_EPS kappa) {worst_ratio:.2}"
        );
        assert!(
            worst_well <= 1e-28,
            "{name}: well-conditioned entries off by {worst_well:e}"
        );
    }
}

/// Test 1 (fixture): the f64 rounding of the reference against every transfer-function value of
/// the mpmath ROMY fixture (1024 bins x (X, phi, phi_a) x (theta_t, eta_t), written with repr).
/// The reference's error is below `DD_REF_FACTOR DD_EPS kappa`, which is checked to be far below
/// half an ulp, so both are correct roundings of the same number: they are equal, or 1 ulp apart
/// when the exact value sits within that error of a rounding boundary.
#[test]
fn reference_rounds_to_the_romy_fixture() {
    let fixture = json("scripts/reference/romy_budget_reference.json");
    let freqs = floats(&fixture["freqs_hz"]);
    let (re, im) = (floats(&fixture["tf"]["re"]), floats(&fixture["tf"]["im"]));
    let outputs: Vec<Observable> = fixture["tf"]["outputs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| {
            *Observable::ALL
                .iter()
                .find(|o| o.name() == v.as_str().unwrap())
                .unwrap()
        })
        .collect();
    let inputs: Vec<Input> = fixture["tf"]["inputs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| Input::from_name(v.as_str().unwrap()).unwrap())
        .collect();
    assert_eq!(outputs, [Observable::X, Observable::Phi, Observable::PhiA]);
    assert_eq!(inputs.len(), 2);
    let request = Request { outputs, inputs };
    let reference = ReferenceModel::new(&Params::table_i());
    let (mut equal, mut one_ulp, mut zeros, mut max_err_bound) = (0, 0, 0, 0.0f64);
    for (k, &f) in freqs.iter().enumerate() {
        let h = reference.eval_dd(&request, f).unwrap();
        let kappa = reference.entry_condition(&request, f).unwrap();
        for (e, z) in h.iter().enumerate() {
            let idx = k * h.len() + e;
            let got = z.to_c64();
            if re[idx] == 0.0 && im[idx] == 0.0 && z.is_zero() {
                zeros += 1;
                continue;
            }
            max_err_bound = max_err_bound.max(DD_REF_FACTOR * DD_EPS * kappa[e]);
            let d = ulps(got.re, re[idx]).max(ulps(got.im, im[idx]));
            assert!(
                d <= 1,
                "bin {k} ({f} Hz) entry {e}: reference {got} vs fixture {} + {}i ({d} ulp)",
                re[idx],
                im[idx]
            );
            if d == 0 {
                equal += 1;
            } else {
                one_ulp += 1;
            }
        }
    }
    println!(
        "ROMY fixture: {equal} entries identical, {one_ulp} 1 ulp apart, {zeros} exact zeros \
         (structural, both); reference error bound <= {max_err_bound:.1e} relative"
    );
    assert!(
        max_err_bound < 2f64.powi(-60),
        "reference not accurate enough to round: {max_err_bound:e}"
    );
    // The fixture's check: H_X,eta_t(0) = -1.664 m/rad exactly after rounding.
    let at0 = reference.eval(&Request::all_tilt(), 0.0).unwrap();
    let x_eta = at0[Observable::X.index() * 3 + TiltAxis::EtaT.index()];
    assert_eq!(
        x_eta,
        Complex64::new(
            fixture["checks"]["H_X_eta_t_at_0_Hz"].as_f64().unwrap(),
            0.0
        )
    );
    assert_eq!(x_eta.re, -1.664);
}

/// Test 2: the quasi-static limits (f = 0) to double-double precision; every other entry of the
/// 7 x 3 tilt matrix is exactly 0.
#[test]
fn quasi_static_limits_to_dd_precision() {
    let p = Params::table_i();
    let reference = ReferenceModel::new(&p);
    let h = reference.eval_dd(&Request::all_tilt(), 0.0).unwrap();
    let l = &p.length;
    let lever = Dd::from(l.z_m) + Dd::from(l.z_b_m) + Dd::from(l.h_c_m);
    let expected = [
        (Observable::X, TiltAxis::EtaT, -lever),
        (Observable::Y, TiltAxis::ThetaT, lever),
        (Observable::Z, TiltAxis::ThetaT, -Dd::from(l.d_m)),
        (Observable::Theta, TiltAxis::ThetaT, Dd::ONE),
        (Observable::Eta, TiltAxis::EtaT, Dd::ONE),
    ];
    for o in Observable::ALL {
        for t in TiltAxis::ALL {
            let got = h[o.index() * 3 + t.index()];
            match expected.iter().find(|e| e.0 == o && e.1 == t) {
                Some(&(_, _, want)) => {
                    let err = rel_dd(got, CDd::real(want));
                    assert!(
                        err <= 1e-30,
                        "{}/{}: {got:?} vs {want:?} ({err:e})",
                        o.name(),
                        t.name()
                    );
                    println!(
                        "f = 0: {}/{} = {:.17} rel err {err:.1e}",
                        o.name(),
                        t.name(),
                        got.re.to_f64()
                    );
                }
                None => assert!(
                    got.is_zero(),
                    "{}/{} = {got:?} is not exactly 0",
                    o.name(),
                    t.name()
                ),
            }
        }
    }
}

/// Test 3: the low-frequency power laws per eta_t, log-log slope between 1e-6 and 1e-5 Hz:
/// phi and phi_a ~ f^4 (the exact cancellation of the tilt's rotation and translation parts),
/// X + (Z + Z_b + h_c) ~ f^2. The reference resolves them (its error there is about
/// `DD_EPS kappa ~ 1e-21`) and reproduces the fixture's mpmath slopes.
#[test]
fn low_frequency_power_laws() {
    let p = Params::table_i();
    let reference = ReferenceModel::new(&p);
    let request = Request {
        outputs: vec![Observable::X, Observable::Phi, Observable::PhiA],
        inputs: vec![Input::Tilt(TiltAxis::EtaT)],
    };
    let l = &p.length;
    let lever = Dd::from(l.z_m) + Dd::from(l.z_b_m) + Dd::from(l.h_c_m);
    let (f1, f2) = (1e-6, 1e-5);
    let (h1, h2) = (
        reference.eval_dd(&request, f1).unwrap(),
        reference.eval_dd(&request, f2).unwrap(),
    );
    let kappa = reference.entry_condition(&request, f1).unwrap();
    let fixture = json("scripts/reference/romy_budget_reference.json");
    let slopes = &fixture["checks"]["low_f_loglog_slopes_1e-6_to_1e-5_Hz_per_eta_t"];
    for (k, (name, offset, power)) in [
        ("X_plus_lever", lever, 2.0),
        ("phi", Dd::ZERO, 4.0),
        ("phi_a", Dd::ZERO, 4.0),
    ]
    .into_iter()
    .enumerate()
    {
        let v1 = h1[k] + CDd::real(offset);
        let v2 = h2[k] + CDd::real(offset);
        let ratio = (v2.norm_sqr() / v1.norm_sqr()).sqrt().to_f64();
        let slope = ratio.log10() / (f2 / f1).log10();
        let want = slopes[name].as_f64().unwrap();
        println!(
            "slope of {name:12} 1e-6..1e-5 Hz: {slope:.12} (mpmath fixture {want:.12}), reference \
             error bound at 1e-6 Hz {:.0e}",
            DD_REF_FACTOR * DD_EPS * kappa[k]
        );
        assert!((slope - power).abs() < 1e-4, "{name}: slope {slope}");
        assert!(
            (slope - want).abs() < 1e-12,
            "{name}: slope {slope} vs mpmath {want}"
        );
    }
}

/// Section IV.B's decomposition, checked on the reference's own double-double matrices: the tilt
/// forcing per unit t'' equals a rigid rotation of the frame plus the translation of the
/// suspension point, `G2 + M S_rot = -B F_trans` with `F_i = -m_i (w' x (0, 0, h))`,
/// `w' = -e_axis`, to 1e-30 of the entries involved.
#[test]
fn tilt_is_rotation_plus_translation() {
    let p = Params::table_i();
    let reference = ReferenceModel::new(&p);
    let (g2, mass, force) = (
        reference.tilt_g2(),
        reference.mass(),
        reference.force_matrix(),
    );
    let h = Dd::from(p.length.h_m);
    for (axis, rot) in [(0, 0), (1, 1), (2, 2)] {
        // w' x (0, 0, h) with w' = -e_axis: (-e_x) x h e_z = h e_y, (-e_y) x h e_z = -h e_x.
        let acc = match axis {
            0 => [Dd::ZERO, h, Dd::ZERO],
            1 => [-h, Dd::ZERO, Dd::ZERO],
            _ => [Dd::ZERO; 3],
        };
        let mut load = [Dd::ZERO; 12];
        for k in 0..3 {
            load[k] = -(Dd::from(p.mass.m_a_kg) * acc[k]);
            load[3 + k] = -(Dd::from(p.mass.m_b_kg) * acc[k]);
        }
        for r in 0..8 {
            let mut bf = Dd::ZERO;
            for c in 0..12 {
                bf += force[r][c] * load[c];
            }
            let residual = g2[r][axis] + mass[r][rot] + bf;
            let scale =
                g2[r][axis].abs().to_f64() + mass[r][rot].abs().to_f64() + bf.abs().to_f64();
            assert!(
                residual.abs().to_f64() <= 1e-30 * scale.max(1e-300),
                "axis {axis} row {r}: residual {residual:?} of {scale:e}"
            );
        }
    }
}

/// The two independent builds of the matrices agree: the reference's double-double entries
/// rounded to f64 against the library's f64 model, same zero pattern, and each entry within a
/// few ulps of the terms it is made of.
#[test]
fn matrices_agree_with_the_f64_model() {
    let p = damped_params();
    let model = Model::new(&p).unwrap();
    let reference = ReferenceModel::new(&p);
    let mut worst = 0.0f64;
    let mut compare = |what: &str, r: usize, c: usize, lib: f64, dd: Dd| {
        let got = dd.to_f64();
        assert_eq!(
            lib == 0.0,
            got == 0.0,
            "{what}[{r}][{c}]: zero pattern differs ({lib} vs {got})"
        );
        if lib != 0.0 {
            let rel = ((Dd::from(lib) - dd) / dd).abs().to_f64();
            worst = worst.max(rel);
            assert!(
                rel <= 16.0 * f64::EPSILON,
                "{what}[{r}][{c}]: {lib} vs {got} (rel {rel:e})"
            );
        }
    };
    let stiffness = model.stiffness_complex();
    for r in 0..8 {
        for c in 0..8 {
            compare("M", r, c, model.mass()[(r, c)], reference.mass()[r][c]);
            compare(
                "K.re",
                r,
                c,
                stiffness[(r, c)].re,
                reference.stiffness()[r][c].re,
            );
            compare(
                "K.im",
                r,
                c,
                stiffness[(r, c)].im,
                reference.stiffness()[r][c].im,
            );
        }
        for c in 0..12 {
            compare(
                "B",
                r,
                c,
                model.force_matrix()[(r, c)],
                reference.force_matrix()[r][c],
            );
        }
        for c in 0..3 {
            compare(
                "G0",
                r,
                c,
                model.tilt_forcing().g0[(r, c)],
                reference.tilt_g0()[r][c],
            );
            compare(
                "G2",
                r,
                c,
                model.tilt_forcing().g2[(r, c)],
                reference.tilt_g2()[r][c],
            );
        }
    }
    for r in 0..7 {
        for c in 0..8 {
            compare(
                "C",
                r,
                c,
                model.observation()[(r, c)],
                reference.observation()[r][c],
            );
        }
    }
    println!("f64 model matrices vs double-double reference: max relative difference {worst:.1e}");
}

/// Mode frequencies of the undamped model from the mpmath fixture (independent of the crate).
fn fixture_modes() -> Vec<f64> {
    floats(&json("scripts/reference/romy_budget_reference.json")["checks"]["mode_frequencies_hz"])
}

/// Test 4: the f64 direct method against the reference on a log grid 1e-5..100 Hz that avoids
/// the modes (relative distance >= 1e-3). Prints the direct method's max relative error per entry
/// of the 7 x 3 tilt matrix (the accuracy column of the methods table) with the entry's
/// condition number in the paper's coordinates where it occurs, and checks every entry against
/// `DIRECT_TOL_FACTOR eps kappa_paper`. Structural zeros are exactly zero in both.
#[test]
fn direct_method_error_per_entry() {
    let p = Params::table_i();
    let model = Model::new(&p).unwrap();
    let reference = ReferenceModel::new(&p);
    let request = Request::all_tilt();
    let direct = plan(&model, &request, Method::Direct).unwrap();
    let modes = fixture_modes();
    let grid: Vec<f64> = log_grid(1e-5, 100.0, 701)
        .into_iter()
        .filter(|f| modes.iter().all(|nu| (f / nu - 1.0).abs() >= 1e-3))
        .collect();
    let n = request.outputs.len() * request.inputs.len();
    // Per entry: max error, its frequency, kappa_paper and cond there; max err / (eps kappa).
    let mut worst = vec![(0.0f64, 0.0, 0.0, 0.0); n];
    let mut worst_ratio = vec![0.0f64; n];
    for &f in &grid {
        let got = direct.eval(f).unwrap();
        let want = reference.eval_dd(&request, f).unwrap();
        let kappa = reference.entry_condition_paper(&request, f).unwrap();
        let cond = reference.condition_number(f).unwrap();
        let err = relative_errors(&got, &want);
        for k in 0..n {
            assert!(
                err[k].is_finite(),
                "entry {k} at {f} Hz: structural zero not exact in the direct method"
            );
            if want[k].is_zero() {
                continue;
            }
            let ratio = err[k] / (f64::EPSILON * kappa[k].max(1.0));
            assert!(
                ratio <= DIRECT_TOL_FACTOR,
                "entry {k} at {f} Hz: direct error {:.1e} = {ratio:.0} eps kappa (kappa {:.1e})",
                err[k],
                kappa[k]
            );
            worst_ratio[k] = worst_ratio[k].max(ratio);
            if err[k] >= worst[k].0 {
                worst[k] = (err[k], f, kappa[k], cond);
            }
        }
    }
    println!(
        "direct method vs reference, {} frequencies in 1e-5..100 Hz (>= 1e-3 from modes):",
        grid.len()
    );
    println!(
        "{:14} {:>9} {:>11} {:>12} {:>9} {:>14}",
        "entry", "max err", "at f (Hz)", "kappa_paper", "cond", "max err/eps k"
    );
    for (o, &out) in request.outputs.iter().enumerate() {
        for (i, &inp) in request.inputs.iter().enumerate() {
            let k = o * request.inputs.len() + i;
            let (e, f, kap, c) = worst[k];
            if f == 0.0 {
                println!("{:14} exact zero", label(out, inp));
            } else {
                println!(
                    "{:14} {e:9.1e} {f:11.3e} {kap:12.1e} {c:9.1e} {:14.2}",
                    label(out, inp),
                    worst_ratio[k]
                );
            }
        }
    }
}

/// Test 5: damping (loss angles 1e-3 on both torsion fibres) and force inputs (M_b.z, F_b.x)
/// beside the tilts through the direct method, against the reference, within the direct method's
/// accuracy `DIRECT_TOL_FACTOR eps kappa_paper`. (The reference itself is checked against mpmath
/// for this damped model in `reference_matches_mpmath_within_its_condition`.)
#[test]
fn damped_model_and_force_inputs_agree_with_direct() {
    let p = damped_params();
    let model = Model::new(&p).unwrap();
    let reference = ReferenceModel::new(&p);
    let request = Request {
        outputs: Observable::ALL.to_vec(),
        inputs: vec![
            Input::Tilt(TiltAxis::ThetaT),
            Input::Tilt(TiltAxis::EtaT),
            Input::Tilt(TiltAxis::PhiT),
            Input::Force(ForceInput::from_name("M_b.z").unwrap()),
            Input::Force(ForceInput::from_name("F_b.x").unwrap()),
        ],
    };
    let direct = plan(&model, &request, Method::Direct).unwrap();
    for f in [1e-4, 1.31e-3, 2.2e-3, 0.0415, 0.4150390625, 0.6, 3.0, 10.0] {
        let got = direct.eval(f).unwrap();
        let want = reference.eval_dd(&request, f).unwrap();
        let kappa = reference.entry_condition_paper(&request, f).unwrap();
        let err = relative_errors(&got, &want);
        let (mut worst_err, mut worst_ratio, mut worst_at) = (0.0f64, 0.0f64, String::new());
        for (o, &out) in request.outputs.iter().enumerate() {
            for (i, &inp) in request.inputs.iter().enumerate() {
                let k = o * request.inputs.len() + i;
                assert!(
                    err[k].is_finite(),
                    "{} at {f} Hz: structural zero not exact",
                    label(out, inp)
                );
                if want[k].is_zero() {
                    continue;
                }
                let ratio = err[k] / (f64::EPSILON * kappa[k].max(1.0));
                assert!(
                    ratio <= DIRECT_TOL_FACTOR,
                    "{} at {f} Hz: direct error {:.1e} = {ratio:.0} eps kappa (kappa {:.1e})",
                    label(out, inp),
                    err[k],
                    kappa[k]
                );
                if err[k] > worst_err {
                    (worst_err, worst_at) = (err[k], label(out, inp));
                }
                worst_ratio = worst_ratio.max(ratio);
            }
        }
        println!(
            "damped, forces: f = {f:<12} direct max rel err {worst_err:.1e} ({worst_at}), \
             max err / (eps kappa_paper) {worst_ratio:.1}"
        );
    }
}

/// Negative, NaN and infinite frequencies are refused with the direct method's error.
#[test]
fn rejects_invalid_frequencies_like_direct() {
    let model = Model::new(&Params::table_i()).unwrap();
    let reference = ReferenceModel::new(&Params::table_i());
    let request = Request::all_tilt();
    let direct = plan(&model, &request, Method::Direct).unwrap();
    for f in [-1.0, -1e-300, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let ours = reference.eval(&request, f).unwrap_err();
        let theirs = direct.eval(f).unwrap_err();
        assert!(
            matches!(ours, TfError::Freq(FreqError::Invalid { .. })),
            "{f}: {ours}"
        );
        assert_eq!(ours.to_string(), theirs.to_string());
        assert!(reference.eval_dd(&request, f).is_err());
        assert!(reference.entry_condition(&request, f).is_err());
        assert!(reference.condition_number(f).is_err());
    }
}

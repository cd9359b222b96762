#include "nlobs/registry/problem_sets/published_set.hpp"

#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

// Every listed root was refined by Newton's method in 60-digit arithmetic (mpmath) from the
// published value, or from the root our own search found where the source lists none, and rounded
// to double: ‖F‖₂ ≤ 5e−15 at each rounded root (the test checks 1e−10). Where a source lists all
// roots (PHCpack's solution lists [Ver99]) or we found them all (Newton from random complex starts
// until the Bézout number of distinct roots appeared), the problem says so; otherwise it lists the
// roots its source reports.
namespace nlobs {
namespace {

Eigen::VectorXd point(std::initializer_list<double> values) {
  Eigen::VectorXd v(static_cast<Index>(values.size()));
  Index i = 0;
  for (const double value : values) v[i++] = value;
  return v;
}

ProblemStart labelled(std::string label, Eigen::VectorXd x, double scale = 1.0) {
  return ProblemStart{.label = std::move(label), .x = std::move(x), .scale = scale};
}

// X² = A for the m×m matrix X stored row by row, A = 1e−4 I + e₁e₂ᵀ: S. J. Hammarling's matrix
// square root, problems 15 (m = 2) and 16 (m = 3) of J. Burkardt's test_nonlin (its start X = I
// and its root 0.01 I + 50 e₁e₂ᵀ). Newton's steps grow from 0.5 to 15 on the way in while ‖F‖
// falls (docs/solvers.md): a test of divergence rules that look at steps only.
TestProblem hammarling(Index m) {
  auto f = [m](const auto& x, auto& out) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    for (Index i = 0; i < m; ++i) {
      for (Index j = 0; j < m; ++j) {
        T s = T(0.0);
        for (Index k = 0; k < m; ++k) s += x[i * m + k] * x[k * m + j];
        const double a = (i == j ? 1e-4 : 0.0) + (i == 0 && j == 1 ? 1.0 : 0.0);
        out[i * m + j] = s - a;
      }
    }
  };
  const Eigen::VectorXd identity = Eigen::MatrixXd::Identity(m, m).reshaped<Eigen::RowMajor>();
  Eigen::MatrixXd root = 0.01 * Eigen::MatrixXd::Identity(m, m);
  root(0, 1) = 50.0;
  const Eigen::VectorXd published = root.reshaped<Eigen::RowMajor>();
  const std::string name = m == 2 ? "hammarling-2x2" : "hammarling-3x3";
  TestProblem p = root_test_problem(
      name, m * m, f, {labelled("x1", identity), labelled("x10", 10.0 * identity, 10.0)});
  // A has the one eigenvalue 1e−4: its primary square roots are ±(the published root), where F
  // vanishes exactly in double (0.01 · 0.01 rounds to 1e−4, 0.01 · 50 to 0.5). For m = 2 they are
  // its only real square roots (A is non-derogatory); for m = 3 the others (X with eigenvalues of
  // both signs) lie on families through singular Jacobians and are not listed.
  p.solutions = {published, -published};
  p.description = m == 2
                      ? "Hammarling's 2x2 matrix square root X^2 = A (Burkardt's test_nonlin 15)"
                      : "Hammarling's 3x3 matrix square root X^2 = A (Burkardt's test_nonlin 16)";
  return p;
}

// Katsura's magnetism problem [Kat90] for N = 5 as PoSSo poses it: unknowns u₀ … u_N with
// u₋ₗ = uₗ and uₗ = 0 for |l| > N, Σₗ uₗ u_{m−l} = u_m (m = 0 … N−1), Σₗ uₗ = 1 (l from −N to N).
// PHCpack's demo file katsura5 [Ver99] (and COCONUT's copy) is not this system (it has x·y + y·z
// for 2(u₃u₄ + u₄u₅) and t² + 2v(x + y + z) for u₂² + 2(u₀u₄ + u₁u₃ + u₁u₅)), so its published
// roots are not roots here: ours are the 16 real ones of the 32 (2^N, all found).
TestProblem katsura() {
  constexpr int N = 5;
  auto f = [](const auto& u, auto& out) {
    using T = typename std::decay_t<decltype(u)>::Scalar;
    const auto at = [&u](int l) { return std::abs(l) <= N ? T(u[std::abs(l)]) : T(0.0); };
    for (int m = 0; m < N; ++m) {
      T s = T(0.0);
      for (int l = -N; l <= N; ++l) s += at(l) * at(m - l);
      out[m] = s - u[m];
    }
    T s = T(0.0);
    for (int l = -N; l <= N; ++l) s += at(l);
    out[N] = s - 1.0;
  };
  // No published start or box (the physical roots have 0 ≤ uₗ ≤ 1, but most real roots do not):
  // the uniform distribution uₗ = 1/(2N + 1), which meets the linear equation, and two constants.
  TestProblem p =
      root_test_problem("katsura", N + 1, f,
                        {labelled("uniform", Eigen::VectorXd::Constant(N + 1, 1.0 / 11.0)),
                         labelled("half", Eigen::VectorXd::Constant(N + 1, 0.5)),
                         labelled("ones", Eigen::VectorXd::Ones(N + 1))});
  p.solutions = {
      point({1.0, 0.0, 0.0, 0.0, 0.0, 0.0}),
      point({0.8446786613203964, 0.14962860168624587, -0.1356855796445561, 0.11732623933000112,
             -0.09607416047368648, 0.042465568441797406}),
      point({0.732553738417775, 0.18633335106043744, -0.0064283132775649, -0.14603990998332658,
             0.18573119727383725, -0.08587319428227073}),
      point({0.7136089301111327, 0.06755550581163615, 0.2271797815859349, -0.15216510912081013,
             -0.1065910096106414, 0.10721636627831414}),
      point({0.6679936937572428, 0.12610332153937454, 0.19882096532353208, -0.22717790297974214,
             0.006578950888426794, 0.06167781834978734}),
      point({0.6539613667614523, 0.2810620635825783, -0.1289941161200314, -0.02432023650169765,
             0.11178834107306407, -0.06651673541463946}),
      point({0.6278865140429886, 0.1510283514575837, 0.11701212812212075, 0.0053560374231352206,
             -0.23921823588158894, 0.151878461857255}),
      point({0.5204695346196184, 0.07334438209537342, 0.09515734453630896, 0.13036256302246704,
             0.18447784519633414, -0.24357690216029282}),
      point({0.4626892651653608, 0.3100445581289618, 0.05114075022854866, -0.10496778611113515,
             -0.07882625381038946, 0.09126409898133377}),
      point({0.4487806451225011, 0.15092280774981795, 0.014321103498219669, 0.22989391519456917,
             0.08290827652103455, -0.20243642552489188}),
      point({0.37149623359971234, 0.120192253881926, 0.25429708729825834, 0.004480534071585164,
             0.10090000006021317, -0.16561799211183886}),
      point({1.0 / 3.0, 0.0, 0.0, 0.0, 0.0, 1.0 / 3.0}),
      point({0.2782191019517861, 0.22325886807752687, 0.16206745239850914, 0.08669661561272554,
             0.017251052932777063, -0.12838353999743168}),
      point({0.2480969098495464, -0.026724387136385388, 0.07077031264077008, 0.0754754688899176,
             -0.028269794653356536, 0.28469994533428106}),
      point({0.24681837229462578, 0.07213056849790045, -0.03199147908792373, -0.02323705181773625,
             0.07617353979493602, 0.28351523646551063}),
      point({0.1556136566248799, 0.04806332802013846, 0.046772265889353244, 0.04503197686767119,
             0.04287866265503713, 0.23944693825536004}),
  };
  p.description = "Katsura's magnetism problem, N = 5 (PoSSo); all 16 real roots of 32";
  return p;
}

// Morgan's economics problem [Mor87, p. 148], as PHCpack's eco5 … eco8 [Ver99]:
// (x_k + Σ_{i=1}^{n−k−1} xᵢ x_{i+k}) xₙ − k = 0 (k = 1 … n−1), x₁ + … + x_{n−1} + 1 = 0.
// PHCpack lists all 8 (n = 5) and 64 (n = 8) roots; the real ones are listed here (its eco5 file
// gives u₅ = 1/x₅ in place of x₅).
TestProblem eco(int n) {
  auto f = [n](const auto& x, auto& out) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    for (int k = 1; k < n; ++k) {
      T s = x[k - 1];
      for (int i = 1; i <= n - k - 1; ++i) s += x[i - 1] * x[i + k - 1];
      out[k - 1] = s * x[n - 1] - static_cast<double>(k);
    }
    T s = T(1.0);
    for (int i = 0; i < n - 1; ++i) s += x[i];
    out[n - 1] = s;
  };
  // No published start or box.
  TestProblem p = root_test_problem("eco", n, f,
                                    {labelled("ones", Eigen::VectorXd::Ones(n)),
                                     labelled("half", Eigen::VectorXd::Constant(n, 0.5)),
                                     labelled("minus-ones", -Eigen::VectorXd::Ones(n))});
  if (n == 5) {
    p.solutions = {
        point({1.0, 1.0, 1.0, -4.0, -1.0}),
        point({0.7947996052511201, -1.144170413811732, 0.03051499046857391, -0.6811441819079621,
               -5.872471800016769}),
        point({-0.0447996052511202, 1.6797771223807283, -1.1668595671254158, -1.4681179500041923,
               -2.7245767276318484}),
        point({-0.25, -0.25, -0.25, -0.25, -16.0}),
    };
  } else {
    constexpr double s = -1.0 / 7.0;
    p.solutions = {
        point({-0.3475156125202294, 1.59955565082714, -0.7141951080636515, 1.3220970404197319,
               0.7678488168410543, -1.9822793228378468, -1.6455114646661986, -4.253996493072134}),
        point({s, s, s, s, s, s, s, -49.0}),
        point({1.599389257124293, 1.299351542532976, -0.16371972464107304, -1.7234009172703337,
               -1.4085903408362763, 1.736529424420716, -2.339559241330302, -2.9920165629230717}),
        point({0.2518736446040636, 1.0912208114082294, -1.1142421117940848, -0.6371519417366686,
               0.2911452761960025, -0.3328783138382896, -0.5499673648392522, -12.728027965888488}),
        point({1.0, 1.0, 1.0, 1.0, 1.0, 1.0, -7.0, -1.0}),
        point({0.6052692125387936, -0.5293864596512925, 1.1585268189920672, 2.026014965669394,
               -1.9841555720804958, -0.4579792560558256, -1.8182897094126411, -3.8497715538747657}),
        point({1.2046584696630864, -0.4666323105787761, -0.8034565962066553, 0.4340262121531496,
               -0.972072018441767, 0.21119002813555293, -0.6077137847245906, -11.51858025266339}),
        point({-0.7422463999814358, 0.6020750900222276, 0.7366348698613789, 0.06997887540047072,
               -0.5553830480454723, -0.6836284496967303, -0.4274309375604388, -16.376914689312116}),
    };
  }
  p.description = n == 5 ? "Morgan's economics problem (PHCpack eco5); all 4 real roots of 8"
                         : "Morgan's economics problem (PHCpack eco8); all 8 real roots of 64";
  return p;
}

// Benchmark i1 of the interval literature [HS95, VMK97]: xᵢ − aᵢ − bᵢ x_j x_k x_l = 0 on
// [−2, 2]¹⁰. b₇ = 0.21180486 as Van Hentenryck et al. print it (PHCpack's i1 has 0.21180484).
// Its one root in the box, the published (0.2578, 0.3811, 0.2787, …) refined; the zero start is
// the box centre.
constexpr double kI1A[10] = {0.25428722, 0.37842197, 0.27162577, 0.19807914, 0.44166728,
                             0.14654113, 0.42937161, 0.07056438, 0.34504906, 0.42651102};
constexpr double kI1B[10] = {0.18324757, 0.16275449, 0.16955071, 0.15585316, 0.19950920,
                             0.18922793, 0.21180486, 0.17081208, 0.19612740, 0.21466544};
// The unknowns of each product, 1-based as published.
constexpr int kI1Unknowns[10][3] = {{4, 3, 9},  {1, 10, 6}, {1, 2, 10}, {7, 1, 6},  {7, 6, 3},
                                    {8, 5, 10}, {2, 5, 8},  {1, 7, 6},  {10, 6, 8}, {4, 8, 1}};

TestProblem i1() {
  auto f = [](const auto& x, auto& out) {
    for (int i = 0; i < 10; ++i) {
      out[i] =
          x[i] - kI1A[i] -
          kI1B[i] * x[kI1Unknowns[i][0] - 1] * x[kI1Unknowns[i][1] - 1] * x[kI1Unknowns[i][2] - 1];
    }
  };
  TestProblem p = root_test_problem("i1", 10, f,
                                    {labelled("centre", Eigen::VectorXd::Zero(10)),
                                     labelled("upper-half", Eigen::VectorXd::Ones(10)),
                                     labelled("lower-half", -Eigen::VectorXd::Ones(10))});
  p.lower = Eigen::VectorXd::Constant(10, -2.0);
  p.upper = Eigen::VectorXd::Constant(10, 2.0);
  p.solutions = {
      point({0.2578333937005036, 0.38109715460280674, 0.2787450173464404, 0.20066896422534358,
             0.44525142484104163, 0.14918391996935457, 0.43200969898372027, 0.07340277777624866,
             0.34596682687555425, 0.4273262759932905})};
  p.description = "interval benchmark i1 (Hong-Stahl; Van Hentenryck et al. 1997), one root in box";
  return p;
}

// Morgan's combustion problem at 3000 K [Mor87] as Van Hentenryck, Michel and Benhamou pose it
// [VMB97], on [0, 1e8]¹⁰: four balances of the elements and six equilibria. The root (the one
// the sources report in the box) is refined from our Newton run; its components run from 6e−11
// to 1.5e−5 and the equilibria's terms from 4e−21 to 2e−12, so ‖F‖₂ ≤ 1e−8 would hold at points
// far from it (the equilibria are below 1e−8 at any x of the scale 1e−5): f_scale, a power of ten
// per equation that puts its largest term at the root in [1, 10), makes the judged residual
// relative, and u_scale, likewise per unknown, gives KINSOL the unknowns' scale (without it
// KINSOL solves it from no start: from 1e−5 it ends at ‖F‖₂ = 9e−21 but ‖D_f F‖₂ = 4.7; with it,
// it solves it from the origin).
TestProblem combustion() {
  auto f = [](const auto& x, auto& out) {
    out[0] = x[1] + 2.0 * x[5] + x[8] + 2.0 * x[9] - 1e-5;
    out[1] = x[2] + x[7] - 3e-5;
    out[2] = x[0] + x[2] + 2.0 * x[4] + 2.0 * x[7] + x[8] + x[9] - 5e-5;
    out[3] = x[3] + 2.0 * x[6] - 1e-5;
    out[4] = 0.5140437e-7 * x[4] - x[0] * x[0];
    out[5] = 0.1006932e-6 * x[5] - 2.0 * x[1] * x[1];
    out[6] = 0.7816278e-15 * x[6] - x[3] * x[3];
    out[7] = 0.1496236e-6 * x[7] - x[0] * x[2];
    out[8] = 0.6194411e-7 * x[8] - x[0] * x[1];
    out[9] = 0.2089296e-14 * x[9] - x[0] * x[1] * x[1];
  };
  // No published start: the origin (the box's lower corner), the scale of the right-hand sides,
  // and ones (five orders of magnitude too large).
  TestProblem p = root_test_problem("combustion", 10, f,
                                    {labelled("zero", Eigen::VectorXd::Zero(10)),
                                     labelled("rhs-scale", Eigen::VectorXd::Constant(10, 1e-5)),
                                     labelled("ones", Eigen::VectorXd::Ones(10))});
  p.lower = Eigen::VectorXd::Zero(10);
  p.upper = Eigen::VectorXd::Constant(10, 1e8);
  p.f_scale = point({1e5, 1e5, 1e5, 1e5, 1e14, 1e13, 1e21, 1e12, 1e14, 1e21});
  p.u_scale = point({1e7, 1e7, 1e5, 1e11, 1e7, 1e6, 1e6, 1e5, 1e7, 1e6});
  p.solutions = {point({1.4709013277154643e-07, 2.2619636102492644e-07, 1.5128076338334037e-05,
                        6.251491476681666e-11, 4.208884800796344e-07, 1.0162512213519656e-06,
                        4.999968742542617e-06, 1.4871923661665964e-05, 5.37117294535301e-07,
                        3.602091950867921e-06})};
  p.description =
      "Morgan's combustion at 3000 K on [0, 1e8] (Van Hentenryck et al.), judged in its f_scale";
  return p;
}

// Meintjes and Morgan's hydrocarbon combustion equilibrium [MM90] in its reduced form, with the
// constants R = 10, R5 = 0.193, R6 = 0.002597/√40, R7 = 0.003448/√40, R8 = 1.799e−5/40,
// R9 = 2.155e−4/√40, R10 = 3.846e−5/40. `handbook` picks the coefficient of R10 y₂² in the second
// equation: 2 as PHCpack's chemequ [Ver99] and the chemistry benchmark of [VMB97] carry it, 3
// (2.8845e−6) in the model of Floudas's handbook, problem 14.1.2 [Flo99]. Each variant has 16
// roots, 4 real (PHCpack lists them for 2; we found the 16 for both), one without a negative
// component.
TestProblem chemical_equilibrium(bool handbook) {
  const double r10_factor = handbook ? 3.0 : 2.0;
  auto f = [r10_factor](const auto& y, auto& out) {
    const double r = 10.0, r5 = 0.193, r6 = 0.002597 / std::sqrt(40.0),
                 r7 = 0.003448 / std::sqrt(40.0), r8 = 0.00001799 / 40.0,
                 r9 = 0.0002155 / std::sqrt(40.0), r10 = 0.00003846 / 40.0;
    out[0] = y[0] * y[1] + y[0] - 3.0 * y[4];
    out[1] = 2.0 * y[0] * y[1] + y[0] + r10_factor * r10 * y[1] * y[1] + y[1] * y[2] * y[2] +
             r7 * y[1] * y[2] + r9 * y[1] * y[3] + r8 * y[1] - r * y[4];
    out[2] = 2.0 * y[1] * y[2] * y[2] + 2.0 * r5 * y[2] * y[2] - 8.0 * y[4] + r6 * y[2] +
             r7 * y[1] * y[2];
    out[3] = r9 * y[1] * y[3] + 2.0 * y[3] * y[3] - 4.0 * r * y[4];
    out[4] = y[0] * y[1] + y[0] + r10 * y[1] * y[1] + y[1] * y[2] * y[2] + r8 * y[1] +
             r5 * y[2] * y[2] + y[3] * y[3] - 1.0 + r6 * y[2] + r7 * y[1] * y[2] + r9 * y[1] * y[3];
  };
  // [VMB97]'s box [0, 1e8]⁵ and three constant starts; the handbook's box [1e−4, 100]⁵, whose
  // model starts GAMS from the lower bounds.
  std::vector<ProblemStart> starts =
      handbook
          ? std::vector<ProblemStart>{labelled("lower", Eigen::VectorXd::Constant(5, 1e-4)),
                                      labelled("ones", Eigen::VectorXd::Ones(5)),
                                      labelled("centre", Eigen::VectorXd::Constant(5, 50.00005))}
          : std::vector<ProblemStart>{labelled("ones", Eigen::VectorXd::Ones(5)),
                                      labelled("tenth", Eigen::VectorXd::Constant(5, 0.1)),
                                      labelled("tens", Eigen::VectorXd::Constant(5, 10.0))};
  TestProblem p =
      root_test_problem(handbook ? "floudas-14.1.2" : "meintjes-morgan", 5, f, std::move(starts));
  if (!handbook) {
    p.lower = Eigen::VectorXd::Zero(5);
    p.upper = Eigen::VectorXd::Constant(5, 1e8);
    // PHCpack's solution 7 (its constants rounded to five digits), refined. The other real roots
    // (its solutions 5, 6 and 9, refined) have y₃ or y₄ < 0: (0.002757, 39.24, −0.06139, 0.8597,
    // 0.03699), (0.002153, 50.55, −0.05414, −0.8607, 0.03700), (0.002471, 43.88, 0.05778,
    // −0.8602, 0.03697).
    p.solutions = {point({0.00311410226598496, 34.59792453029013, 0.06504177869743798,
                          0.8593780505779406, 0.03695185914804602})};
    p.description = "Meintjes-Morgan combustion equilibrium (PHCpack chemequ) on [0, 1e8]";
  } else {
    p.lower = Eigen::VectorXd::Constant(5, 1e-4);
    p.upper = Eigen::VectorXd::Constant(5, 100.0);
    // The other three real roots have y₃ or y₄ < 0.
    p.solutions = {point({0.003430230388273467, 31.326494615912726, 0.0683504038331012,
                          0.859528996160224, 0.036962441392620816})};
    p.description = "Meintjes-Morgan equilibrium as Floudas's handbook 14.1.2 has it, on its box";
  }
  return p;
}

// Brown's almost-linear system [Bro69] for n = 5 on [−2, 2]⁵, problem 14.1.5 of Floudas's handbook
// [Flo99] (MGH's problem 27 [MGH81], whose n = 10 instance is in the mgh set): xᵢ + Σⱼ xⱼ = n + 1
// (i < n), Π xⱼ = 1. Its real roots are (a, a, a, a, 6 − 5a) for the real roots a of
// 5a⁵ − 6a⁴ + 1: a = 1, a = 0.91635… (both listed) and a = −0.57904… (x₅ = 8.9, outside).
TestProblem brown_almost_linear() {
  constexpr int n = 5;
  auto f = [](const auto& x, auto& out) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    T sum = T(0.0), product = T(1.0);
    for (int j = 0; j < n; ++j) {
      sum += x[j];
      product *= x[j];
    }
    for (int i = 0; i < n - 1; ++i) out[i] = x[i] + sum - static_cast<double>(n + 1);
    out[n - 1] = product - 1.0;
  };
  TestProblem p = root_test_problem("brown-almost-linear", n, f,
                                    {labelled("x1", Eigen::VectorXd::Constant(n, 0.5)),
                                     labelled("centre", Eigen::VectorXd::Zero(n)),
                                     labelled("corner", Eigen::VectorXd::Constant(n, 2.0))});
  p.lower = Eigen::VectorXd::Constant(n, -2.0);
  p.upper = Eigen::VectorXd::Constant(n, 2.0);
  constexpr double a = 0.9163545825338494;
  p.solutions = {Eigen::VectorXd::Ones(n), point({a, a, a, a, 1.4182270873307534})};
  p.description = "Brown's almost-linear system, n = 5, on [-2, 2] (Floudas's handbook 14.1.5)";
  return p;
}

// The inverse position problem of a six-revolute-joint manipulator [MS87] as Numerica poses it
// [VMD97] ("kin2"), on [−1, 1]⁸: four unit circles (xᵢ = cos, x_{i+1} = sin of a joint angle)
// and, for j = 1 … 4, x₁(a₁ⱼx₃ + a₂ⱼx₄ + a₉ⱼ) + x₂(a₃ⱼx₃ + a₄ⱼx₄ + a₁₀ⱼ) + x₅(a₅ⱼx₇ + a₆ⱼx₈ + a₁₃ⱼ)
// + x₆(a₇ⱼx₇ + a₈ⱼx₈ + a₁₄ⱼ) + a₁₁ⱼx₃ + a₁₂ⱼx₄ + a₁₅ⱼx₇ + a₁₆ⱼx₈ + a₁₇ⱼ = 0. Its 10 real roots
// as Numerica's interval boxes give them (widths ≤ 8e−10), refined.
// a_{ij}, i = 1 … 17 (row), j = 1 … 4 (column), as Numerica lists them.
constexpr double kKin2A[17][4] = {{-0.24915068, 0.12501635, -0.63555007, 1.4894773},
                                  {1.6091354, -0.68660736, -0.11571992, 0.23062341},
                                  {0.27942343, -0.11922812, -0.66640448, 1.3281073},
                                  {1.4348016, -0.71994047, 0.11036211, -0.25864503},
                                  {0.0, -0.43241927, 0.29070203, 1.1651720},
                                  {0.40026384, 0.0, 1.2587767, -0.26908494},
                                  {-0.80052768, 0.0, -0.62938836, 0.53816987},
                                  {0.0, -0.86483855, 0.58140406, 0.58258598},
                                  {0.074052388, -0.037157270, 0.19594662, -0.20816985},
                                  {-0.083050031, 0.035436896, -1.2280342, 2.6868320},
                                  {-0.38615961, 0.085383482, 0.0, -0.69910317},
                                  {-0.75526603, 0.0, -0.079034221, 0.35744413},
                                  {0.50420168, -0.039251967, 0.026387877, 1.2499117},
                                  {-1.0916287, 0.0, -0.057131430, 1.4677360},
                                  {0.0, -0.43241927, -1.1628081, 1.1651720},
                                  {0.049207290, 0.0, 1.2587767, 1.0763397},
                                  {0.049207290, 0.013873010, 2.1625750, -0.69686809}};

TestProblem kin2() {
  auto f = [](const auto& x, auto& out) {
    for (int i = 0; i < 4; ++i) out[i] = x[2 * i] * x[2 * i] + x[2 * i + 1] * x[2 * i + 1] - 1.0;
    for (int j = 0; j < 4; ++j) {
      const auto c = [j](int i) { return kKin2A[i - 1][j]; };  // a_{ij}, i 1-based as published
      out[4 + j] =
          x[0] * (c(1) * x[2] + c(2) * x[3] + c(9)) + x[1] * (c(3) * x[2] + c(4) * x[3] + c(10)) +
          x[4] * (c(5) * x[6] + c(6) * x[7] + c(13)) + x[5] * (c(7) * x[6] + c(8) * x[7] + c(14)) +
          c(11) * x[2] + c(12) * x[3] + c(15) * x[6] + c(16) * x[7] + c(17);
    }
  };
  // No published start: the box centre (where the circles' gradients vanish) and ±1/2.
  TestProblem p = root_test_problem("kin2", 8, f,
                                    {labelled("centre", Eigen::VectorXd::Zero(8)),
                                     labelled("half", Eigen::VectorXd::Constant(8, 0.5)),
                                     labelled("minus-half", Eigen::VectorXd::Constant(8, -0.5))});
  p.lower = Eigen::VectorXd::Constant(8, -1.0);
  p.upper = Eigen::VectorXd::Constant(8, 1.0);
  p.solutions = {
      point({0.8476730058130445, 0.5305190620664617, 0.9852621644826712, -0.17105106617300497,
             0.4900210554034123, -0.8717105971945769, -0.5519308660423524, -0.8338898722911431}),
      point({0.945504605289938, 0.32560872435412186, 0.9385612473787843, 0.3451127133543189,
             -0.9391447017700489, -0.34352180300127344, 0.8707744714031158, 0.49168264150021024}),
      point({0.9779218582738248, 0.2089709049371926, 0.02611329026245425, 0.9996589898918875,
             -0.09786861128375435, 0.9951993443151926, 0.07707361041455367, -0.9970254051816662}),
      point({0.980793884336528, 0.19504706213646303, -0.9941103362380441, -0.10837268744791251,
             0.8844523117560799, 0.46663059075603497, 0.29434036157423965, -0.9557006600125093}),
      point({0.9527580344562087, 0.30373035373360663, -0.7905265443466392, 0.6124277775243062,
             0.24151152375424004, 0.9703979513034356, 0.23735979607757227, -0.9714218070467706}),
      point({-0.5541951472916777, 0.8323867723110187, 0.5626360082491184, 0.8267047370261633,
             0.8285714395871384, -0.5598833534768622, -0.6908546767710085, -0.7229936483701812}),
      point({-0.5419279206258892, 0.8404249691948116, 0.46704319444754183, 0.8842345019960687,
             -0.8367190935305457, -0.5476323205595356, 0.8951440396911436, 0.445777016237289}),
      point({-0.7675197725113151, 0.6410252715799737, 0.6964160418688368, -0.7176382770085098,
             -0.9999792481477108, -0.006442303465303183, 0.8149506345239275, 0.579530381679035}),
      point({-0.8332582974697361, -0.5528839025490223, -0.9549376539729113, 0.29680646392003057,
             0.8646283146455676, -0.5024120594822198, -0.2334735725858912, -0.9723631476480279}),
      point({-0.9749979044705441, -0.22221405508663894, -0.9938796285858964, -0.11046847460683343,
             -0.9999920795048708, 0.003980066271322633, 0.9983398141291017, -0.057598745860224246}),
  };
  p.description = "6R manipulator inverse position (Morgan-Sommese; Numerica kin2), 10 real roots";
  return p;
}

}  // namespace

ProblemSetEntry published_problem_set() {
  ProblemSetEntry set;
  set.name = "published";
  set.description =
      "polynomial systems of the interval and global-optimization benchmarks with their verified "
      "real roots (Hammarling's square roots, Katsura, eco, i1, combustion, Meintjes-Morgan, "
      "Floudas 14.1.2 and 14.1.5, kin2); engines that take bounds get the published boxes";
  set.problems = [] {
    std::vector<TestProblem> problems;
    problems.push_back(hammarling(2));
    problems.push_back(hammarling(3));
    problems.push_back(katsura());
    problems.push_back(eco(5));
    problems.push_back(eco(8));
    problems.push_back(i1());
    problems.push_back(combustion());
    problems.push_back(chemical_equilibrium(false));
    problems.push_back(chemical_equilibrium(true));
    problems.push_back(brown_almost_linear());
    problems.push_back(kin2());
    return problems;
  };
  return set;
}

}  // namespace nlobs

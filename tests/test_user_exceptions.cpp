// Exceptions from user code (docs/extending.md, "Exceptions from user code"): an engine's solve()
// lets whatever a user's F or Jacobian throws — a std::exception or not (`throw 42`) — reach its
// caller unchanged, including the engines that run a C or C++ library underneath (NLopt, Ceres:
// caught at the library's boundary, rethrown after it returns), and the polyalgorithm rethrows
// when every stage threw. Every engine of the registry, at a dynamic and a fixed size.
#include <gtest/gtest.h>

#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "nlobs/solvers/engine_registry.hpp"

namespace nlobs {
namespace {

// Every spec the registry lists: each engine's name and its examples, and NLopt with a gradient.
template <int N>
std::vector<std::string> every_engine_spec() {
  std::set<std::string> specs;
  for (const auto& e : EngineRegistry<N>::global().entries()) {
    specs.insert(e.name);
    for (const std::string& example : e.examples) specs.insert(example);
  }
  specs.insert("nlopt:LD_SLSQP");
  specs.insert("newton:linesearch=1");
  specs.insert("newton:trustregion=1");
  return {specs.begin(), specs.end()};
}

enum class Throws { kInt, kRuntimeError };

// G(x) = cos(x) per entry (a contraction: every engine takes it), with ∂G by hand; from the
// (after + 1)-th evaluation of G on (or of ∂G when `jacobian`), every evaluation throws.
template <int N>
FixedPointProblem<N> throwing_problem(Index n, int after, Throws what, bool jacobian, int* count) {
  const auto maybe_throw = [what, after, count] {
    if (++*count > after) {
      if (what == Throws::kInt) throw 42;
      throw std::runtime_error("the user's G gave up");
    }
  };
  return FixedPointProblem<N>::with_jacobian(
      [=](const Vector<N>& x, Vector<N>& g) {
        if (!jacobian) maybe_throw();
        g = x.array().cos().matrix();
      },
      [=](const Vector<N>& x, Matrix<N, N>& j) {
        if (jacobian) maybe_throw();
        j = (-x.array().sin()).matrix().asDiagonal();
      },
      n);
}

// What reached the caller of solve(): "42", the runtime_error's text, or "returned <status>".
template <int N>
std::string outcome(Engine<N>& engine, const FixedPointProblem<N>& problem, Index n) {
  Vector<N> x = Vector<N>::Constant(n, 0.3);
  try {
    const Summary s = engine.solve(problem, x);
    return "returned " + std::string(to_string(s.status)) + " (" + s.message + ")";
  } catch (int v) {
    return std::to_string(v);
  } catch (const std::runtime_error& e) {
    return e.what();
  } catch (...) {
    return "another exception";
  }
}

template <int N>
void every_engine_lets_the_exception_through(Index n) {
  for (const std::string& spec : every_engine_spec<N>()) {
    for (const bool jacobian : {false, true}) {
      for (const Throws what : {Throws::kInt, Throws::kRuntimeError}) {
        for (const int after : {0, 3}) {
          SCOPED_TRACE(spec + (jacobian ? ", Jacobian" : ", G") +
                       (what == Throws::kInt ? " throws 42" : " throws runtime_error") + " after " +
                       std::to_string(after));
          std::unique_ptr<Engine<N>> engine = EngineRegistry<N>::global().create(spec);
          int count = 0;
          const auto problem = throwing_problem<N>(n, after, what, jacobian, &count);
          const std::string got = outcome<N>(*engine, problem, n);
          if (count <= after) {
            // Never reached the throwing call: only an engine that uses no Jacobian (the
            // fixed-point engines, derivative-free NLopt) may solve without it.
            EXPECT_TRUE(jacobian) << got;
            EXPECT_EQ(got.rfind("returned", 0), 0u) << got;
            continue;
          }
          EXPECT_EQ(got, what == Throws::kInt ? "42" : "the user's G gave up");
          // The engine is whole afterwards: on a problem that does not throw it answers as a
          // fresh engine does.
          int unused = 0;
          const auto fine = throwing_problem<N>(n, 1 << 30, what, jacobian, &unused);
          Vector<N> x = Vector<N>::Constant(n, 0.3), fresh_x = x;
          const Summary s = engine->solve(fine, x);
          const Summary fresh = EngineRegistry<N>::global().create(spec)->solve(fine, fresh_x);
          EXPECT_EQ(s.status, fresh.status) << s.full_report();
          EXPECT_EQ(x, fresh_x);
        }
      }
    }
  }
}

TEST(UserExceptions, EveryEngineLetsAUsersExceptionReachItsCaller) {
  every_engine_lets_the_exception_through<Dynamic>(2);
}

TEST(UserExceptions, EveryFixedSizeEngineLetsAUsersExceptionReachItsCaller) {
  every_engine_lets_the_exception_through<3>(3);
}

}  // namespace
}  // namespace nlobs

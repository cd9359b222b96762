// One registry mechanism (nlobs/common/named_registry.hpp) behind engines, models, observer
// types and problem sets: the same refusals in the same words for each kind, added directly or
// through a plugin's registrar, and its thread rule (any member from any thread, add() included;
// entries never move).
#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <thread>
#include <vector>

#include "invalid_argument_message.hpp"
#include "nlobs/common/named_registry.hpp"
#include "nlobs/registry/model_registry.hpp"
#include "nlobs/registry/observer_types.hpp"
#include "nlobs/registry/problem_sets.hpp"
#include "nlobs/solvers/engine_registry.hpp"

namespace nlobs {
namespace {

// A model entry of that name and nothing else (GCC warns of designated initialisers that leave
// members without defaults out).
ModelEntry model_named(const std::string& name) {
  ModelEntry e;
  e.name = name;
  return e;
}

// "w<w>-<i>", built by appending (GCC 12 warns of a false overlap in "w" + to_string(w) + …).
std::string writer_name(int w, int i) {
  std::string name = "w";
  name += std::to_string(w);
  name += '-';
  name += std::to_string(i);
  return name;
}

using test::message_of;

// Every kind refuses an entry without the function that builds it, in one shape: "<kind> '<name>'
// from <source> <what is missing>", adding nothing; a taken name names both sources.
TEST(NamedRegistry, EveryKindRefusesAnIncompleteOrTakenEntryInTheSameWords) {
  EXPECT_EQ(message_of([] { model_registry().add(model_named("no-make"), "a test"); }),
            "model 'no-make' from a test has no make");
  EXPECT_FALSE(model_registry().contains("no-make"));
  ObserverTypeEntry type;
  type.name = "no-build";
  type.parse = [](JsonReader&, const ModelInstance&) { return std::any(); };
  type.write = [](const std::any&, nlohmann::json&) {};
  EXPECT_EQ(message_of([&] { observer_type_registry().add(type, "a test"); }),
            "observer type 'no-build' from a test needs parse, write and build");
  EXPECT_FALSE(observer_type_registry().contains("no-build"));
  EXPECT_EQ(message_of([] {
              problem_set_registry().add(ProblemSetEntry{.name = "no-problems"}, "a test");
            }),
            "problem set 'no-problems' from a test has no problems()");
  EXPECT_EQ(
      message_of([] { EngineRegistry<Dynamic>::global().add({.name = "no-factory"}, "a test"); }),
      "engine 'no-factory' from a test has no factory");
  EXPECT_FALSE(EngineRegistry<Dynamic>::global().contains("no-factory"));
  // A taken name, before completeness: both sources named.
  EXPECT_EQ(message_of([] { model_registry().add(model_named("lorenz"), "a test"); }),
            "model 'lorenz' from a test is already registered by built-in");
  EXPECT_EQ(message_of([] { EngineRegistry<Dynamic>::global().add({.name = "newton"}, "a test"); }),
            "engine 'newton' from a test is already registered by built-in");
  // refusal() says the same without throwing, and nothing when the entry would be taken.
  EXPECT_EQ(model_registry().refusal(model_named("no-make"), "a test"),
            "model 'no-make' from a test has no make");
  EXPECT_EQ(
      message_of([] {
        model_registry().get("nonesuch");
      }).rfind("unknown model 'nonesuch'; valid models: modified-chua, cubic-chua, lorenz", 0),
      0u);
}

struct Named {
  std::string name;
  int value = 0;
};

// Writers and readers at once: every entry lands once, a pointer taken early still points at
// its entry after hundreds more were added, and a reader never sees a half-added one.
TEST(NamedRegistry, AddFindAndListFromManyThreadsAtOnce) {
  NamedRegistry<Named> registry("thing");
  registry.add({"first", -1});
  const Named* first = registry.find("first");
  ASSERT_NE(first, nullptr);
  constexpr int kWriters = 4, kEach = 300;
  std::atomic<bool> writing{true};
  std::atomic<long> seen{0};
  std::thread reader([&] {
    do {  // at least one pass, however fast the writers are
      for (const Named* e : registry.entries()) {
        if (registry.find(e->name) != e) ADD_FAILURE() << "find() moved " << e->name;
        ++seen;
      }
    } while (writing.load());
  });
  std::vector<std::thread> writers;
  for (int w = 0; w < kWriters; ++w) {
    writers.emplace_back([&registry, w] {
      for (int i = 0; i < kEach; ++i) {
        const std::string name = writer_name(w, i);
        registry.add({name, w * kEach + i}, std::string("writer ").append(std::to_string(w)));
        // Taken from then on, for every thread.
        EXPECT_FALSE(registry.refusal({name, 0}, "late").empty());
      }
    });
  }
  for (auto& t : writers) t.join();
  writing = false;
  reader.join();
  EXPECT_GT(seen.load(), 0);
  EXPECT_EQ(registry.names().size(), 1u + kWriters * kEach);
  EXPECT_EQ(registry.find("first"), first);
  EXPECT_EQ(first->value, -1);
  for (int w = 0; w < kWriters; ++w) {
    for (int i = 0; i < kEach; ++i) {
      const std::string name = writer_name(w, i);
      const Named* e = registry.find(name);
      ASSERT_NE(e, nullptr) << name;
      EXPECT_EQ(e->value, w * kEach + i);
      EXPECT_EQ(registry.source(name), std::string("writer ").append(std::to_string(w)));
    }
  }
}

// The engine registry is one of them: engines created on two threads while a third registers
// new ones.
TEST(NamedRegistry, TheEngineRegistryCreatesWhileAnotherThreadRegisters) {
  auto& registry = EngineRegistry<Dynamic>::global();
  std::atomic<bool> adding{true};
  std::vector<std::thread> creators;
  std::atomic<int> created{0};
  for (int c = 0; c < 2; ++c) {
    creators.emplace_back([&] {
      do {  // at least once, however fast the registrations are
        if (registry.create("anderson:depth=2") != nullptr) ++created;
      } while (adding.load());
    });
  }
  for (int i = 0; i < 200; ++i) {
    registry.add({.name = std::string("copy-").append(std::to_string(i)),
                  .make =
                      [](EngineSpecReader&, SolverOptions o) {
                        return EngineRegistry<Dynamic>::global().create("picard", o);
                      }},
                 "a test");
  }
  adding = false;
  for (auto& t : creators) t.join();
  EXPECT_GT(created.load(), 0);
  EXPECT_TRUE(registry.contains("copy-199"));
  EXPECT_EQ(registry.create("copy-7")->name(), "picard");
  // At a fixed size the new entries come through the Dynamic fallback.
  EXPECT_TRUE(EngineRegistry<3>::global().contains("copy-199"));
}

}  // namespace
}  // namespace nlobs

// The training plan's checks on the way (pipeline/adapt_run.h: NextPlanCheck, Replan).

#include <gtest/gtest.h>

#include "pipeline/adapt_run.h"

namespace handlabel::adapt {
namespace {

// The development recording's run of 2026-12-07: 2486 steps planned from the timing
// run's 1.31 s/step, which then ran at about 1.5.
nlohmann::json FirstPlan() {
  return {{"steps", 2486},          {"seconds_per_step", 1.31},
          {"budget_seconds", 3600}, {"seconds_before_training", 46.0},
          {"reserve_seconds", 158}, {"checkpoint_every", 120},
          {"validate_every", 200}};
}

TEST(AdaptPlan, ChecksComeEveryTenthOfTheStepsBeforeTheDecay) {
  // After the 20 timed steps, every 248 steps (a tenth) up to 70 % of 2486 (1740).
  std::vector<int64_t> at;
  for (int64_t s = NextPlanCheck(FirstPlan(), 20); s > 0;
       s = NextPlanCheck(FirstPlan(), s)) {
    at.push_back(s);
    if (at.size() > 20) break;
  }
  EXPECT_EQ(at, (std::vector<int64_t>{268, 516, 764, 1012, 1260, 1508}));
  EXPECT_EQ(NextPlanCheck({{"steps", 200}}, 20), 120);  // at least 100 steps measured
  EXPECT_EQ(NextPlanCheck({{"steps", 200}}, 120), 0);   // 220 is past the decay (140)
  EXPECT_EQ(NextPlanCheck({{"steps", 40}}, 20), 0);     // too short for a check
  // A run continued at step 700 of the first plan measures at least half a tenth.
  EXPECT_EQ(NextPlanCheck(FirstPlan(), 700), 1012);
  EXPECT_EQ(NextPlanCheck(FirstPlan(), 600), 764);
}

TEST(AdaptPlan, StepsMeasuredSlowerThanPlannedFitTheBudgetAgain) {
  const nlohmann::json first = FirstPlan();
  // Steps 20-268 took 1.53 s each. Planned on, the run would end 377 s late:
  const double late = 46 + 2466 * 1.53 + 158 - 3600;
  EXPECT_GT(late, 370);
  nlohmann::json plan = first;
  Replan(268, 1.53, 248 * 1.53, &plan);
  const int64_t steps = plan["steps"];
  EXPECT_LT(steps, 2486);
  EXPECT_EQ(plan["first_plan_steps"], 2486);
  ASSERT_EQ(plan["checks"].size(), 1u);
  EXPECT_EQ(plan["checks"][0]["at_step"], 268);
  // At the measured rate the whole run now ends within the budget, using 95 % of it.
  const double end = 46 + 248 * 1.53 + (steps - 268) * 1.53 + 158;
  EXPECT_LE(end, 3600);
  EXPECT_GT(end, 0.95 * 3600);
  // Only the number of steps changes: checkpoints and validation keep their spacing.
  EXPECT_EQ(plan["checkpoint_every"], 120);
  EXPECT_EQ(plan["validate_every"], 200);

  // Faster than planned: more steps. No time left: the fewest (20 more).
  nlohmann::json faster = first;
  Replan(268, 1.1, 248 * 1.1, &faster);
  EXPECT_GT(faster["steps"].get<int64_t>(), 2486);
  nlohmann::json over = first;
  Replan(268, 20.0, 248 * 20.0, &over);
  EXPECT_EQ(over["steps"], 288);
}

TEST(AdaptPlan, ALaterCheckCountsTheTimeOfTheEarlierOnes) {
  // Another process takes half the machine after the first check: steps slow from 1.3
  // to 2.6 s. The second check plans on the new rate and the time spent so far.
  nlohmann::json plan = FirstPlan();
  Replan(268, 1.3, 248 * 1.3, &plan);
  const int64_t second = NextPlanCheck(plan, 268);
  ASSERT_GT(second, 268);
  Replan(second, 2.6, (second - 268) * 2.6, &plan);
  ASSERT_EQ(plan["checks"].size(), 2u);
  EXPECT_EQ(plan["first_plan_steps"], 2486);  // the first plan, not the first check's
  const double spent = 46 + 248 * 1.3 + (second - 268) * 2.6;
  EXPECT_NEAR(plan["checks"][1]["seconds_spent"].get<double>(), spent, 1e-9);
  const int64_t steps = plan["steps"];
  const double end = spent + (steps - second) * 2.6 + 158;
  EXPECT_LE(end, 3600);
  EXPECT_GT(end, 0.95 * 3600 - 2.6);
}

TEST(AdaptPlan, APlanFromAnOlderRunContinuesAfterItsSingleCheck) {
  nlohmann::json plan = FirstPlan();
  plan["steps"] = 2140;
  plan["first_plan_steps"] = 2486;
  plan["replanned"] = {
      {"at_step", 248}, {"seconds_per_step", 1.53}, {"seconds_spent", 395}};
  EXPECT_EQ(NextPlanCheck(plan, 248), 248 + 214);
  Replan(462, 1.5, 214 * 1.5, &plan);
  EXPECT_FALSE(plan.contains("replanned"));
  ASSERT_EQ(plan["checks"].size(), 2u);
  EXPECT_NEAR(plan["checks"][1]["seconds_spent"].get<double>(), 395 + 214 * 1.5, 1e-9);
}

}  // namespace
}  // namespace handlabel::adapt

// The training plan's check on the way (pipeline/adapt_run.h: ReplanStep, Replan).

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

TEST(AdaptPlan, TheCheckComesAfterATenthOfTheStepsAndOnlyInLongPlans) {
  EXPECT_EQ(ReplanStep(FirstPlan()), 248);
  EXPECT_EQ(ReplanStep({{"steps", 200}}), 100);  // at least 100 steps measured
  EXPECT_EQ(ReplanStep({{"steps", 199}}), 0);    // too short to check before its middle
  EXPECT_EQ(ReplanStep({{"steps", 40}}), 0);
}

TEST(AdaptPlan, StepsMeasuredSlowerThanPlannedFitTheBudgetAgain) {
  const nlohmann::json first = FirstPlan();
  // Steps 20-248 took 1.53 s each. Planned on, the run would end 377 s late:
  const double late = 46 + 2466 * 1.53 + 158 - 3600;
  EXPECT_GT(late, 370);
  nlohmann::json plan = first;
  Replan(248, 1.53, 228 * 1.53, &plan);
  const int64_t steps = plan["steps"];
  EXPECT_LT(steps, 2486);
  EXPECT_EQ(plan["first_plan_steps"], 2486);
  EXPECT_EQ(plan["replanned"]["at_step"], 248);
  // At the measured rate the whole run now ends within the budget, using 95 % of it.
  const double end = 46 + 228 * 1.53 + (steps - 248) * 1.53 + 158;
  EXPECT_LE(end, 3600);
  EXPECT_GT(end, 0.95 * 3600);
  // Only the number of steps changes: checkpoints and validation keep their spacing.
  EXPECT_EQ(plan["checkpoint_every"], 120);
  EXPECT_EQ(plan["validate_every"], 200);

  // Faster than planned: more steps. No time left: the fewest (20 more).
  nlohmann::json faster = first;
  Replan(248, 1.1, 228 * 1.1, &faster);
  EXPECT_GT(faster["steps"].get<int64_t>(), 2486);
  nlohmann::json over = first;
  Replan(248, 20.0, 228 * 20.0, &over);
  EXPECT_EQ(over["steps"], 268);
}

}  // namespace
}  // namespace handlabel::adapt

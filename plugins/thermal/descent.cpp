#include "descent.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bodyfit::thermal {

double Descent::merit(double j, double area) const {
  double m = j + options_.ell * area;
  if (options_.target) {
    const double gap = area - *options_.target;
    m += lambda_ * gap + 0.5 * options_.penalty * gap * gap;
  }
  return m;
}

double Descent::area_weight(double area) const {
  double weight = options_.ell;
  if (options_.target) weight += lambda_ + options_.penalty * (area - *options_.target);
  return weight;
}

Descent::Verdict Descent::judge(double current_j, double current_area, double slope, double dt, double speed,
                                double j, double area, int attempt) {
  const double now = merit(current_j, current_area), next = merit(j, area);
  Verdict v;
  v.bound = now + options_.armijo * dt * slope + options_.noise * std::abs(now);
  v.accept = next <= v.bound;
  if (attempt == 0) last_deviation_ = 0;
  if (!v.accept) {
    const double deviation = next - (now + dt * slope);
    if (attempt >= 1 && last_deviation_ > 0 && next > now && deviation > 0.5 * last_deviation_)
      options_.noise = std::max(options_.noise, std::min(options_.max_noise, 2 * (next - now) / std::abs(now)));
    last_deviation_ = deviation;
  }
  // Even the shortest step raises M: not an ascent direction but a jump of the discretisation (a
  // part of G thinner than an element is lost in the cut whatever the step). Take it and go on.
  if (!v.accept && dt * speed <= options_.min_step * (1 + 1e-12)) v.accept = v.forced = true;
  return v;
}

void Descent::accept(double j, double area) {
  records_.push_back({j, area, 0, stage()});
  // The multiplier's update after every update_every accepted steps (the first state included).
  if (options_.target && records_.size() % std::size_t(options_.update_every) == 0)
    lambda_ += options_.penalty * (area - *options_.target);
}

void Descent::set_slope(double slope) {
  if (!records_.empty()) records_.back().slope = slope;
}

double Descent::next_step(double dt, double speed, int attempt, bool rose, double next_speed) {
  const double limit = options_.max_motion > 0 ? options_.max_motion : std::numeric_limits<double>::infinity();
  if (motion_ == 0) motion_ = limit;
  const double taken = dt * speed;
  if (rose) motion_ = 0.5 * std::min(motion_, taken);
  else if (attempt > 0) motion_ = std::min(motion_, taken);
  else motion_ = std::min(motion_ * options_.grow, limit);
  double next = attempt == 0 && !rose ? dt * options_.grow : dt;
  if (next_speed > 0) next = std::min(next, motion_ / next_speed);
  if (options_.max_step > 0) next = std::min(next, options_.max_step);
  return std::max(next, options_.min_step);
}

void Descent::new_stage(double j, double area) {
  const int next = stage() + 1;
  records_.push_back({j, area, 0, next});
  motion_ = 0;  // a new problem: the trust region starts again at max_motion
}

double Descent::stage_step(double next_speed) const {
  double next = options_.max_step > 0 ? options_.max_step : std::numeric_limits<double>::infinity();
  if (options_.max_motion > 0 && next_speed > 0) next = std::min(next, options_.max_motion / next_speed);
  return std::isfinite(next) ? std::max(next, options_.min_step) : 0.0;
}

std::string Descent::stop_reason() const {
  auto begin = records_.begin();
  while (begin != records_.end() && begin->stage != stage()) ++begin;
  const std::vector<DescentRecord> stage_records(begin, records_.end());
  if (stage_records.size() < 2) return {};
  const DescentRecord& last = stage_records.back();
  const double first_slope = stage_records.front().slope;
  const bool on_target = !options_.target ||
                         std::abs(last.area - *options_.target) <= options_.area_tolerance * *options_.target;
  if (options_.stationarity > 0 && first_slope < 0 && last.slope <= 0 &&
      std::abs(last.slope) <= options_.stationarity * std::abs(first_slope) && on_target)
    return fmt::format("stationary: |M'(v)| = {:.3g} is {:.3g} of its first value (stationarity {:g})",
                       std::abs(last.slope), std::abs(last.slope / first_slope), options_.stationarity);
  const std::size_t k = std::size_t(options_.patience);
  if (stage_records.size() <= k + 1 || !on_target) return {};
  // The merits at today's multiplier, so that a change of λ is not read as progress.
  std::vector<double> m(stage_records.size());
  for (std::size_t i = 0; i < m.size(); ++i) m[i] = merit(stage_records[i].j, stage_records[i].area);
  const auto recent = m.end() - std::ptrdiff_t(k);
  const double best_before = *std::min_element(m.begin(), recent);
  const double best_recent = *std::min_element(recent, m.end());
  const double floor = std::max(options_.tolerance, options_.noise);
  if (best_recent >= best_before - floor * std::abs(best_before))
    return fmt::format("stalled: the best merit improved by less than {:.3g} (relative, max of tolerance and noise) "
                       "over the last {} accepted steps (merit {:.8g}, best {:.8g})",
                       floor, k, m.back(), std::min(best_before, best_recent));
  return {};
}

}  // namespace bodyfit::thermal

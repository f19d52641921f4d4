#pragma once
// The per-kind tables behind schema/params.hpp (internal to engine/schema).
#include "schema/params.hpp"

namespace ks {
std::vector<ParamDef> trajectory_params(const KindContext& context);
std::vector<MetricDef> trajectory_metrics(const KindContext& context);
std::vector<ParamDef> ik_params(const KindContext& context);
std::vector<MetricDef> ik_metrics(const KindContext& context);
std::vector<ParamDef> motion_params(const KindContext& context);
std::vector<MetricDef> motion_metrics(const KindContext& context);
}  // namespace ks

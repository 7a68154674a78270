#include "network/poem/poem_config.h"

#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "core/option_checks.h"
#include "core/text.h"

namespace handlabel {
namespace {

using Json = nlohmann::json;

std::string RangeString(const std::array<double, 6>& r) {
  std::vector<std::string> items;
  for (const double value : r) items.push_back(FormatNumber(value));
  return "[" + Join(items) + "]";
}

}  // namespace

std::array<int, 4> PoemConfig::stage_blocks() const {
  if (backbone == "resnet18") return {2, 2, 2, 2};
  return {3, 4, 6, 3};  // resnet34
}

void PoemConfig::Check(const std::string& source) const {
  if (backbone != "resnet18" && backbone != "resnet34") {
    throw InputError(source, "backbone", "resnet18 or resnet34", backbone);
  }
  RequireGreater(source, "backbone_width", backbone_width, 0, "a positive value");
  RequireInRange(source, "num_views", num_views, 1, 64);
  if (crop_size < 32 || crop_size % 32 != 0) {
    throw InputError(source, "crop_size", "a positive multiple of 32",
                     std::to_string(crop_size));
  }
  RequireGreater(source, "depth_bins", depth_bins, 0, "a positive value");
  if (embed_dim < 4 || embed_dim % 4 != 0) {
    throw InputError(source, "embed_dim", "a positive multiple of 4",
                     std::to_string(embed_dim));
  }
  RequireGreater(source, "transformer_dim", transformer_dim, 0, "a positive value");
  RequireGreater(source, "num_decoder_blocks", num_decoder_blocks, 0, "a positive value");
  RequireGreater(source, "point_neighbors", point_neighbors, 0, "a positive value");
  RequireGreater(source, "query_neighbors", query_neighbors, 0, "a positive value");
  RequireAtMost(source, "query_neighbors", query_neighbors, kNumQueries,
                "at most " + std::to_string(kNumQueries));
  if (num_sampled_points < point_neighbors) {
    throw InputError(source, "num_sampled_points",
                     "at least point_neighbors (" + std::to_string(point_neighbors) + ")",
                     std::to_string(num_sampled_points));
  }
  const long long frustum_points =
      static_cast<long long>(num_views) * heatmap_size() * heatmap_size() * depth_bins;
  if (num_sampled_points > frustum_points) {
    throw InputError(source, "num_sampled_points",
                     "at most the frustum point count " + std::to_string(frustum_points),
                     std::to_string(num_sampled_points));
  }
  RequireGreater(source, "ball_radius", ball_radius, 0, "a positive value");
  for (int a = 0; a < 3; ++a) {
    if (!(position_range[a + 3] > position_range[a])) {
      throw InputError(source, "position_range",
                       "[xmin, ymin, zmin, xmax, ymax, zmax] with max > min per axis",
                       RangeString(position_range));
    }
  }
  if (!(position_range[2] >= 0)) {
    throw InputError(source, "position_range", "zmin >= 0 (depths in front of cameras)",
                     RangeString(position_range));
  }
}

std::string PoemConfig::ToJson() const {
  Json j;
  j["backbone"] = backbone;
  j["backbone_width"] = backbone_width;
  j["num_views"] = num_views;
  j["crop_size"] = crop_size;
  j["depth_bins"] = depth_bins;
  j["embed_dim"] = embed_dim;
  j["transformer_dim"] = transformer_dim;
  j["num_decoder_blocks"] = num_decoder_blocks;
  j["point_neighbors"] = point_neighbors;
  j["query_neighbors"] = query_neighbors;
  j["num_sampled_points"] = num_sampled_points;
  j["ball_radius"] = ball_radius;
  j["position_range"] = position_range;
  j["mask_head"] = mask_head;
  return j.dump(2);
}

PoemConfig PoemConfig::FromJson(const std::string& text, const std::string& source) {
  Json j;
  try {
    j = Json::parse(text);
  } catch (const std::exception& e) {
    throw InputError(source, "", "a JSON object", e.what());
  }
  if (!j.is_object()) throw InputError(source, "", "a JSON object", j.type_name());
  PoemConfig c;
  for (const auto& [key, value] : j.items()) {
    try {
      if (key == "backbone")
        c.backbone = value.get<std::string>();
      else if (key == "backbone_width")
        c.backbone_width = value.get<int>();
      else if (key == "num_views")
        c.num_views = value.get<int>();
      else if (key == "crop_size")
        c.crop_size = value.get<int>();
      else if (key == "depth_bins")
        c.depth_bins = value.get<int>();
      else if (key == "embed_dim")
        c.embed_dim = value.get<int>();
      else if (key == "transformer_dim")
        c.transformer_dim = value.get<int>();
      else if (key == "num_decoder_blocks")
        c.num_decoder_blocks = value.get<int>();
      else if (key == "point_neighbors")
        c.point_neighbors = value.get<int>();
      else if (key == "query_neighbors")
        c.query_neighbors = value.get<int>();
      else if (key == "num_sampled_points")
        c.num_sampled_points = value.get<int>();
      else if (key == "ball_radius")
        c.ball_radius = value.get<double>();
      else if (key == "position_range")
        c.position_range = value.get<std::array<double, 6>>();
      else if (key == "mask_head")
        c.mask_head = value.get<bool>();
      else
        throw InputError(source, key, "a known POEM config field", "unknown field");
    } catch (const Json::exception& e) {
      throw InputError(source, key, "a value of the right type", e.what());
    }
  }
  c.Check(source);
  return c;
}

std::vector<std::string> PoemConfig::Differences(const PoemConfig& o) const {
  std::vector<std::string> d;
  auto cmp = [&](const char* name, const std::string& a, const std::string& b) {
    if (a != b) d.push_back(std::string(name) + ": " + a + " vs " + b);
  };
  // Numbers compare as their message text (6 significant digits).
  auto cmp_number = [&](const char* name, double a, double b) {
    cmp(name, FormatNumber(a), FormatNumber(b));
  };
  cmp("backbone", backbone, o.backbone);
  cmp_number("backbone_width", backbone_width, o.backbone_width);
  cmp_number("num_views", num_views, o.num_views);
  cmp_number("crop_size", crop_size, o.crop_size);
  cmp_number("depth_bins", depth_bins, o.depth_bins);
  cmp_number("embed_dim", embed_dim, o.embed_dim);
  cmp_number("transformer_dim", transformer_dim, o.transformer_dim);
  cmp_number("num_decoder_blocks", num_decoder_blocks, o.num_decoder_blocks);
  cmp_number("point_neighbors", point_neighbors, o.point_neighbors);
  cmp_number("query_neighbors", query_neighbors, o.query_neighbors);
  cmp_number("num_sampled_points", num_sampled_points, o.num_sampled_points);
  cmp_number("ball_radius", ball_radius, o.ball_radius);
  cmp("position_range", RangeString(position_range), RangeString(o.position_range));
  cmp("mask_head", mask_head ? "true" : "false", o.mask_head ? "true" : "false");
  return d;
}

PoemConfig ReleasedPoemConfig(int num_views) {
  PoemConfig c;
  c.num_views = num_views;
  return c;
}

PoemConfig ReleasedPoemConfig(PoemDataset dataset) {
  switch (dataset) {
    case PoemDataset::kDexYCB: {
      PoemConfig c = ReleasedPoemConfig(8);
      c.position_range = {-1.2, -1.2, 0.2, 1.2, 1.2, 2.0};
      return c;
    }
    case PoemDataset::kOakInk: {
      PoemConfig c = ReleasedPoemConfig(4);
      c.position_range = {-1.0, -1.0, 0.0, 1.0, 1.0, 1.5};
      return c;
    }
    case PoemDataset::kHO3D: {
      PoemConfig c = ReleasedPoemConfig(5);
      c.position_range = {-0.6, -0.6, 0.0, 0.6, 0.6, 1.2};
      return c;
    }
  }
  return PoemConfig();
}

PoemConfig SmallPoemConfig(int num_views) {
  PoemConfig c;
  c.backbone = "resnet18";
  c.backbone_width = 32;
  c.num_views = num_views;
  c.crop_size = 128;
  c.depth_bins = 16;
  c.embed_dim = 64;
  c.transformer_dim = 64;
  c.num_decoder_blocks = 3;
  c.point_neighbors = 8;
  c.query_neighbors = 8;
  c.num_sampled_points = 1024;
  return c;
}

PoemConfig TinyPoemConfig(int num_views) {
  PoemConfig c;
  c.backbone = "resnet18";
  c.backbone_width = 8;
  c.num_views = num_views;
  c.crop_size = 64;
  c.depth_bins = 8;
  c.embed_dim = 16;
  c.transformer_dim = 16;
  c.num_decoder_blocks = 2;
  c.point_neighbors = 8;
  c.query_neighbors = 8;
  c.num_sampled_points = 256;
  return c;
}

PoemConfig PoemConfigByName(const std::string& name, int num_views) {
  if (name == "released-dexycb") return ReleasedPoemConfig(PoemDataset::kDexYCB);
  if (name == "released-oakink") return ReleasedPoemConfig(PoemDataset::kOakInk);
  if (name == "released-ho3d") return ReleasedPoemConfig(PoemDataset::kHO3D);
  if (name == "small") return SmallPoemConfig(num_views);
  if (name == "tiny") return TinyPoemConfig(num_views);
  throw InputError("POEM config name", "name",
                   "released-dexycb, released-oakink, released-ho3d, small or tiny",
                   name);
}

}  // namespace handlabel

#pragma once
/// The scene's sections that map onto one module's parameters (`tool`, `holder`, `field`,
/// `dynamics`, `path`, `links`), each read and checked key by key (DESIGN.md "Scene file").
#include <yaml-cpp/yaml.h>

#include "fieldpath/dynamics/params.h"
#include "fieldpath/field/params.h"
#include "fieldpath/geometry/tool.h"
#include "fieldpath/pathgen/params.h"
#include "scene_reader.h"

namespace fieldpath::app {

void readTool(const Reader& r, const YAML::Node& node, geometry::ToolSpec& tool);
void readHolder(const Reader& r, const YAML::Node& node, geometry::HolderProfile& holder);
void readField(const Reader& r, const YAML::Node& node, field::FieldParams& f);
void readDynamics(const Reader& r, const YAML::Node& node, dynamics::DynamicsParams& d);
void readPath(const Reader& r, const YAML::Node& node, pathgen::PathParams& p);
void readLinks(const Reader& r, const YAML::Node& node, pathgen::LinkParams& links);

}  // namespace fieldpath::app

// PCD loading through PCL (pcl::io::loadPCDFile into a PCLPointCloud2, then
// the typed conversions), copied into our own Cloud.
#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <stdexcept>

#include "iplan/cloud/cloud.h"

namespace iplan::cloud {
namespace {

bool HasField(const pcl::PCLPointCloud2& blob, const std::string& name) {
  return pcl::getFieldIndex(blob, name) >= 0;
}

// The field layout the typed conversions below assume: x y z float32, one
// value each; rgb/rgba and label four bytes. Empty when it holds.
std::string CheckLayout(const pcl::PCLPointCloud2& header) {
  for (const auto& f : header.fields) {
    const bool xyz = f.name == "x" || f.name == "y" || f.name == "z";
    if (xyz && (f.datatype != pcl::PCLPointField::FLOAT32 || f.count != 1))
      return "field '" + f.name + "' must be one float32 (F 4 1)";
    const bool four = f.name == "rgb" || f.name == "rgba" || f.name == "label";
    if (four && (pcl::getFieldSize(f.datatype) != 4 || f.count != 1))
      return "field '" + f.name + "' must be one 4-byte value";
  }
  return "";
}

}  // namespace

Cloud LoadPcd(const std::string& path) {
  pcl::PCLPointCloud2 blob;
  pcl::PCDReader reader;
  // The header first: PCDReader::read crashes (PCL 1.13) on some files
  // whose header it cannot parse, so only a sound header reaches it.
  {
    pcl::PCLPointCloud2 header;
    Eigen::Vector4f origin;
    Eigen::Quaternionf orientation;
    int version = 0, binary = 0;
    unsigned int data_offset = 0;
    if (reader.readHeader(path, header, origin, orientation, version, binary, data_offset) < 0)
      throw std::runtime_error(path + ": cannot read PCD file");
    if (!HasField(header, "x") || !HasField(header, "y") || !HasField(header, "z"))
      throw std::runtime_error(path + ": PCD file has no x y z fields");
    if (const std::string why = CheckLayout(header); !why.empty()) throw std::runtime_error(path + ": " + why);
    if (static_cast<std::size_t>(header.width) * header.height == 0)
      throw std::runtime_error(path + ": PCD file has no points");
  }
  if (reader.read(path, blob) < 0) throw std::runtime_error(path + ": cannot read PCD file");
  const std::size_t n = static_cast<std::size_t>(blob.width) * blob.height;
  if (n * blob.point_step != blob.data.size())
    throw std::runtime_error(path + ": width * height * point_step (" + std::to_string(n) + " * " +
                             std::to_string(blob.point_step) + ") != data size " +
                             std::to_string(blob.data.size()));
  Cloud out;
  out.width = static_cast<int>(blob.width);
  out.height = static_cast<int>(blob.height);
  pcl::PointCloud<pcl::PointXYZ> xyz;
  pcl::fromPCLPointCloud2(blob, xyz);
  out.points.resize(n);
  for (std::size_t i = 0; i < n; ++i) out.points[i] = xyz[i].getVector3fMap();
  if (HasField(blob, "rgba") || HasField(blob, "rgb")) {
    pcl::PointCloud<pcl::PointXYZRGBA> colour;
    pcl::fromPCLPointCloud2(blob, colour);
    out.rgba.resize(n);
    for (std::size_t i = 0; i < n; ++i) out.rgba[i] = colour[i].rgba;
  }
  if (HasField(blob, "label")) {
    pcl::PointCloud<pcl::Label> labels;
    pcl::fromPCLPointCloud2(blob, labels);
    out.label.resize(n);
    for (std::size_t i = 0; i < n; ++i) out.label[i] = labels[i].label;
  }
  return out;
}

}  // namespace iplan::cloud

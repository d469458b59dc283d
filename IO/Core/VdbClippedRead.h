// VdbClippedRead: a grid that, read by OpenVDB's Archive::readGrid with an index box, keeps
// only the part of the tree that touches the box, topology included (included by VdbGrids.cxx
// only; it includes OpenVDB).
//
// OpenVDB's own clipped read (Grid::readTopology, then Grid::readBuffers(is, box)) builds the
// whole tree's topology first -- every internal node and one leaf object per leaf of 512
// voxels, about 100 bytes each: 1.6 GiB for a dense 2048^3 grid -- and drops the nodes outside
// the box only when their voxel buffers have been read. ClippedGrid overrides those two steps
// and reads the same bytes with OpenVDB's own node classes, in the order they are stored:
//
//  * topology: the root's tiles, the upper internal nodes (32^3 tiles of 128^3 voxels), the
//    lower internal nodes (16^3 leaves, 128^3 voxels) and the leaves' value masks are read
//    here as RootNode's and InternalNode's readTopology read them (NodeMask::load,
//    io::readCompressedValues, LeafNode::readTopology); a node or leaf is kept only if it
//    touches the box, and of each lower node the mask of its leaves, to read their buffers;
//  * buffers: as InternalNode::readBuffers(is, box): the kept leaves read their buffers
//    (LeafNode::readBuffers), the others are skipped in the stream (their value mask, stored
//    again before their values, then io::readCompressedValues without a destination, which
//    seeks); each kept lower node is clipped; then RootNode::clip as RootNode::readBuffers ends.
//
// The tree held is the box's part: its leaves, the lower and upper nodes that hold them, and
// 512 bytes per lower node of the grid (its leaf mask). Inside the box the tree's values are those
// of OpenVDB's clipped read, tile for tile and voxel for voxel (the same decoding calls on the same
// bytes); outside it both hold the background. Given the box's dense array, the grid writes the
// values there instead (each leaf decoded into a buffer of 512 values and copied as soon as its
// buffer is read, the tiles and the background as they are read; the nodes' copyToDense conversion,
// DenseValueT(value)), and holds no leaves: only the upper nodes and the leaf masks of the lower
// nodes. A damaged stream throws from a node that is whole (ReadLower), so that unwinding frees it
// safely. Format versions before node-mask compression (OpenVDB 3, file format 222) are left to
// OpenVDB (MakeClippedGrid returns null).
#ifndef NimbusVdbClippedRead_h
#define NimbusVdbClippedRead_h

#include <openvdb/Grid.h>
#include <openvdb/io/Compression.h>
#include <openvdb/io/io.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <vector>

namespace nimbus
{
namespace vdb
{

template <typename TreeT, typename DenseValueT>
class ClippedGrid : public openvdb::Grid<TreeT>
{
public:
  using DenseT = openvdb::tools::Dense<DenseValueT, openvdb::tools::LayoutXYZ>;
  using RootT = typename TreeT::RootNodeType;
  using UpperT = typename RootT::ChildNodeType;
  using LowerT = typename UpperT::ChildNodeType;
  using LeafT = typename LowerT::ChildNodeType;
  using ValueT = typename TreeT::ValueType;
  static_assert(
    RootT::LEVEL == 3 && LeafT::LEVEL == 0, "a tree of root, 2 internal levels, leaves");

  /// With `values` (the box's points, x fastest, as DenseValueT), the values go straight there:
  /// each leaf is copied (LeafNode::copyToDense) as soon as its buffer is read, then freed; the
  /// tiles and the background are written as they are read; the tree stays empty.
  ClippedGrid(const openvdb::CoordBBox& clip, DenseValueT* values)
    : Clip(clip)
  {
    if (values)
    {
      this->Target.reset(new DenseT(clip, values));
    }
  }

  using openvdb::Grid<TreeT>::readBuffers;

  void readTopology(std::istream& is) override
  {
    this->Uppers.clear();
    TreeT& tree = this->tree();
    tree.clear();
    const bool fromHalf = this->saveFloatAsHalf();
    // The per-leaf table of OpenVDB's delayed loading (a mask byte and a compressed size per
    // leaf, held for the whole read) only spares the skipped leaves two small reads; without it
    // io::readCompressedValues reads them from the stream, to the same values.
    if (const auto meta = openvdb::io::getStreamMetadataPtr(is))
    {
      meta->gridMetadata().removeMeta(openvdb::GridBase::META_FILE_DELAYED_LOAD);
    }
    int32_t bufferCount = 0; // TreeBase::readTopology
    is.read(reinterpret_cast<char*>(&bufferCount), sizeof(int32_t));
    // RootNode::readTopology (the current format).
    ValueT background;
    is.read(reinterpret_cast<char*>(&background), sizeof(ValueT));
    tree.root().setBackground(background, /*updateChildNodes=*/false);
    openvdb::io::setGridBackgroundValuePtr(is, &tree.root().background());
    this->Fill(this->Clip, background);
    openvdb::Index numTiles = 0, numChildren = 0;
    is.read(reinterpret_cast<char*>(&numTiles), sizeof(openvdb::Index));
    is.read(reinterpret_cast<char*>(&numChildren), sizeof(openvdb::Index));
    for (openvdb::Index n = 0; n < numTiles; ++n)
    {
      openvdb::Int32 vec[3];
      ValueT value;
      bool active = false;
      is.read(reinterpret_cast<char*>(vec), 3 * sizeof(openvdb::Int32));
      is.read(reinterpret_cast<char*>(&value), sizeof(ValueT));
      is.read(reinterpret_cast<char*>(&active), sizeof(bool));
      const openvdb::Coord key(vec);
      if (key == (key & ~(UpperT::DIM - 1))) // the root finds only tiles at its keys
      {
        tree.root().addTile(key, value, active);
        this->Fill(openvdb::CoordBBox::createCube(key, UpperT::DIM), value);
      }
    }
    for (openvdb::Index n = 0; n < numChildren; ++n)
    {
      openvdb::Int32 vec[3];
      is.read(reinterpret_cast<char*>(vec), 3 * sizeof(openvdb::Int32));
      // As RootNode's table, the children's buffers follow in the order of their origins
      // (a repeated origin replaces the earlier child).
      this->Uppers[openvdb::Coord(vec)] = this->ReadUpper(is, openvdb::Coord(vec), fromHalf);
    }
  }

  void readBuffers(std::istream& is, const openvdb::CoordBBox& bbox) override
  {
    if (bbox != this->Clip)
    {
      throw std::logic_error("ClippedGrid: readBuffers with another box than its own");
    }
    const bool fromHalf = this->saveFloatAsHalf();
    RootT& root = this->tree().root();
    for (auto& entry : this->Uppers)
    {
      Upper& upper = entry.second;
      for (const Lower& lower : upper.Children)
      {
        this->ReadLowerBuffers(is, lower, fromHalf);
      }
      if (upper.Node && !this->Target)
      {
        root.addChild(upper.Node.release());
      }
    }
    this->Uppers.clear();
    if (this->Target)
    {
      root.clear();
    }
    else
    {
      root.clip(this->Clip);
    }
  }

private:
  struct Lower
  {
    LowerT* Node = nullptr; // kept (owned by its upper node, at Offset) or null
    bool Copied = false;    // with a target: it touches the box (no node is kept)
    openvdb::Index Offset = 0;
    openvdb::Coord Origin;
    /// The file's leaves, in the order of their buffers; Node holds those that touch the box.
    typename LowerT::NodeMaskType Leaves;
  };
  struct Upper
  {
    std::unique_ptr<UpperT> Node; // null when it does not touch the box, or with a target
    std::vector<Lower> Children;  // in the order of their buffers
  };

  /// InternalNode::readTopology of an upper node (format >= 222), keeping what touches the box.
  Upper ReadUpper(std::istream& is, const openvdb::Coord& origin, bool fromHalf)
  {
    const ValueT& background = this->tree().root().background();
    // The root finds children only at its keys (an origin off them is read and dropped).
    const openvdb::Coord snapped = origin & ~(UpperT::DIM - 1);
    const bool keep = origin == snapped &&
      this->Clip.hasOverlap(openvdb::CoordBBox::createCube(snapped, UpperT::DIM));
    Upper upper;
    if (keep && !this->Target) // with a target its tiles go there, its leaves too: no node
    {
      upper.Node.reset(new UpperT(snapped, background, /*active=*/false));
    }
    typename UpperT::NodeMaskType childMask, valueMask;
    childMask.load(is);
    valueMask.load(is);
    {
      std::unique_ptr<ValueT[]> values(new ValueT[UpperT::NUM_VALUES]);
      openvdb::io::readCompressedValues(is, values.get(), UpperT::NUM_VALUES, valueMask, fromHalf);
      for (openvdb::Index i = 0; keep && i < UpperT::NUM_VALUES; ++i)
      {
        if (!childMask.isOn(i) && upper.Node)
        {
          upper.Node->addTile(i, values[i], valueMask.isOn(i));
        }
        else if (!childMask.isOn(i))
        {
          this->Fill(
            openvdb::CoordBBox::createCube(UpperChildOrigin(i, snapped), LowerT::DIM), values[i]);
        }
      }
    }
    for (auto it = childMask.beginOn(); it; ++it)
    {
      Lower record;
      record.Offset = it.pos();
      record.Origin = UpperChildOrigin(it.pos(), snapped);
      std::unique_ptr<LowerT> lower = this->ReadLower(is, record.Origin, keep, fromHalf, record);
      if (lower)
      {
        record.Node = lower.get();
        upper.Node->addChild(lower.release());
      }
      upper.Children.push_back(record);
    }
    return upper;
  }

  /// The origin of child `n` of the upper node at `origin` (InternalNode::offsetToGlobalCoord).
  static openvdb::Coord UpperChildOrigin(openvdb::Index n, const openvdb::Coord& origin)
  {
    openvdb::Coord local;
    UpperT::offsetToLocalCoord(n, local);
    return (local << LowerT::TOTAL) + origin;
  }

  /// InternalNode::readTopology of a lower node (format >= 222): the node, if `keep` and it
  /// touches the box, with only the leaves that touch the box (`leaves` receives the file's);
  /// null otherwise. In an order that leaves the node whole if the stream fails half-way
  /// (OpenVDB's sets the child mask before the children, so a node it stops reading cannot be
  /// deleted): the masks and tile values first, then each leaf (PartialCreate: no buffer yet)
  /// put in the node before its mask is read.
  std::unique_ptr<LowerT> ReadLower(
    std::istream& is, const openvdb::Coord& origin, bool keep, bool fromHalf, Lower& record)
  {
    const ValueT& background = this->tree().root().background();
    typename LowerT::NodeMaskType& leaves = record.Leaves;
    typename LowerT::NodeMaskType valueMask;
    leaves.load(is);
    valueMask.load(is);
    std::unique_ptr<ValueT[]> values(new ValueT[LowerT::NUM_VALUES]);
    openvdb::io::readCompressedValues(is, values.get(), LowerT::NUM_VALUES, valueMask, fromHalf);
    std::unique_ptr<LowerT> lower;
    const bool touches =
      keep && this->Clip.hasOverlap(openvdb::CoordBBox::createCube(origin, LowerT::DIM));
    if (touches && this->Target)
    {
      // Its tiles go to the target now, its leaves when their buffers come (CopyLeafBuffer):
      // no node, no leaf objects.
      record.Copied = true;
      for (openvdb::Index i = 0; i < LowerT::NUM_VALUES; ++i)
      {
        if (!leaves.isOn(i))
        {
          this->Fill(openvdb::CoordBBox::createCube(ChildOrigin(i, origin), LeafT::DIM), values[i]);
        }
      }
    }
    else if (touches)
    {
      lower.reset(new LowerT(origin, background, /*active=*/false));
      for (openvdb::Index i = 0; i < LowerT::NUM_VALUES; ++i)
      {
        if (!leaves.isOn(i))
        {
          lower->addTile(i, values[i], valueMask.isOn(i));
        }
      }
    }
    typename LeafT::NodeMaskType skipped;
    for (auto it = leaves.beginOn(); it; ++it)
    {
      const openvdb::Coord at = ChildOrigin(it.pos(), origin);
      if (lower && this->Clip.hasOverlap(openvdb::CoordBBox::createCube(at, LeafT::DIM)))
      {
        auto* leaf = new LeafT(openvdb::PartialCreate(), at, background);
        lower->addChild(leaf);
        leaf->readTopology(is, fromHalf);
      }
      else
      {
        skipped.load(is); // LeafNode::readTopology of a leaf that is not kept
      }
    }
    return lower;
  }

  /// InternalNode::readBuffers(is, box) of a lower node as read by ReadLower: the kept leaves'
  /// buffers read (LeafNode::readBuffers), the others skipped; then the node clipped. With a
  /// target, the leaves that touch the box are read into it (CopyLeafBuffer).
  void ReadLowerBuffers(std::istream& is, const Lower& lower, bool fromHalf)
  {
    LowerT* node = lower.Node;
    for (auto it = lower.Leaves.beginOn(); it; ++it)
    {
      const openvdb::Coord at = ChildOrigin(it.pos(), lower.Origin);
      if (lower.Copied && this->Clip.hasOverlap(openvdb::CoordBBox::createCube(at, LeafT::DIM)))
      {
        this->CopyLeafBuffer(is, at, fromHalf);
      }
      else if (LeafT* leaf = node ? node->probeLeaf(at) : nullptr)
      {
        leaf->readBuffers(is, this->Clip, fromHalf);
      }
      else
      {
        SkipLeafBuffer(is, fromHalf);
      }
    }
    if (node)
    {
      node->clip(this->Clip, this->tree().root().background());
    }
  }

  /// LeafNode::readBuffers then LeafNode::copyToDense of a leaf at `origin` that touches the
  /// box, without a leaf: its value mask (stored again before its values), its values decoded
  /// (io::readCompressedValues) into a buffer, the box's part written to the target as
  /// DenseValueT(value).
  void CopyLeafBuffer(std::istream& is, const openvdb::Coord& origin, bool fromHalf)
  {
    typename LeafT::NodeMaskType mask;
    mask.load(is);
    ValueT values[LeafT::SIZE];
    openvdb::io::readCompressedValues(is, values, LeafT::SIZE, mask, fromHalf);
    if (const auto meta = openvdb::io::getStreamMetadataPtr(is))
    {
      meta->setLeaf(meta->leaf() + 1); // as LeafNode::readBuffers counts leaves
    }
    openvdb::CoordBBox part = openvdb::CoordBBox::createCube(origin, LeafT::DIM);
    part.intersect(this->Clip);
    const size_t n = size_t(part.max()[0] - part.min()[0] + 1);
    for (openvdb::Int32 k = part.min()[2]; k <= part.max()[2]; ++k)
    {
      for (openvdb::Int32 j = part.min()[1]; j <= part.max()[1]; ++j)
      {
        DenseValueT* row =
          this->Target->data() + this->Target->coordToOffset(openvdb::Coord(part.min()[0], j, k));
        for (size_t i = 0; i < n; ++i)
        {
          const openvdb::Coord xyz(part.min()[0] + openvdb::Int32(i), j, k);
          row[i] = DenseValueT(values[LeafT::coordToOffset(xyz)]);
        }
      }
    }
  }

  /// The origin of child `n` of the lower node at `origin` (InternalNode::offsetToGlobalCoord).
  static openvdb::Coord ChildOrigin(openvdb::Index n, const openvdb::Coord& origin)
  {
    openvdb::Coord local;
    LowerT::offsetToLocalCoord(n, local);
    return (local << LeafT::TOTAL) + origin;
  }

  /// Skips a leaf's buffer (LeafNode::readBuffers of a leaf outside the box): its value mask,
  /// stored again before its values, then the values, sought over.
  static void SkipLeafBuffer(std::istream& is, bool fromHalf)
  {
    typename LeafT::NodeMaskType mask;
    mask.load(is);
    openvdb::io::readCompressedValues<ValueT, typename LeafT::NodeMaskType>(
      is, nullptr, LeafT::SIZE, mask, fromHalf);
    if (const auto meta = openvdb::io::getStreamMetadataPtr(is))
    {
      meta->setLeaf(meta->leaf() + 1); // as LeafNode::readBuffers counts leaves
    }
  }

  /// Writes `value` at the target's points in `region` (as the nodes' copyToDense writes a
  /// tile: DenseValueT(value)).
  void Fill(openvdb::CoordBBox region, const ValueT& value)
  {
    if (!this->Target)
    {
      return;
    }
    region.intersect(this->Clip);
    if (region.empty())
    {
      return;
    }
    const DenseValueT v = DenseValueT(value);
    const size_t n = size_t(region.max()[0] - region.min()[0] + 1);
    for (openvdb::Int32 k = region.min()[2]; k <= region.max()[2]; ++k)
    {
      for (openvdb::Int32 j = region.min()[1]; j <= region.max()[1]; ++j)
      {
        DenseValueT* row =
          this->Target->data() + this->Target->coordToOffset(openvdb::Coord(region.min()[0], j, k));
        std::fill(row, row + n, v);
      }
    }
  }

  openvdb::CoordBBox Clip;
  std::unique_ptr<DenseT> Target;
  std::map<openvdb::Coord, Upper> Uppers;
};

/// A ClippedGrid for `grid`'s type (float, double, Vec3s, Vec3d trees) with its half-float
/// setting, to be read with Archive::readGrid(grid, descriptor, stream, clip); with `values`,
/// one that writes the values of `clip` there (floats, 3 per point for vector grids) and keeps
/// no tree. Null for other types and for files older than node-mask compression (OpenVDB reads
/// those itself).
inline openvdb::GridBase::Ptr MakeClippedGrid(const openvdb::GridBase& grid, uint32_t formatVersion,
  const openvdb::CoordBBox& clip, float* values = nullptr)
{
  if (formatVersion < openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION)
  {
    return nullptr;
  }
  auto* vectors = reinterpret_cast<openvdb::Vec3s*>(values);
  openvdb::GridBase::Ptr clipped;
  if (grid.isType<openvdb::FloatGrid>())
  {
    clipped = std::make_shared<ClippedGrid<openvdb::FloatTree, float>>(clip, values);
  }
  else if (grid.isType<openvdb::DoubleGrid>())
  {
    clipped = std::make_shared<ClippedGrid<openvdb::DoubleTree, float>>(clip, values);
  }
  else if (grid.isType<openvdb::Vec3SGrid>())
  {
    clipped = std::make_shared<ClippedGrid<openvdb::Vec3STree, openvdb::Vec3s>>(clip, vectors);
  }
  else if (grid.isType<openvdb::Vec3DGrid>())
  {
    clipped = std::make_shared<ClippedGrid<openvdb::Vec3DTree, openvdb::Vec3s>>(clip, vectors);
  }
  if (clipped)
  {
    clipped->setSaveFloatAsHalf(grid.saveFloatAsHalf());
  }
  return clipped;
}

} // namespace vdb
} // namespace nimbus

#endif

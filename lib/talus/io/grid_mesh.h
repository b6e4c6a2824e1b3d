// talus — a first-order quad/hex grid as plain arrays (no deal.II types), the
// exchange format between talus-mesh and the solvers, and its file: gmsh MSH 2.2
// ASCII, which deal.II's GridIn::read_msh(std::istream &) also reads (physical
// tag of a cell = material id, of a boundary line/quad = boundary id).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace talus::io
{
  struct GridMesh
  {
    unsigned int dim = 2;
    /// Vertex coordinates, 3 per vertex (z = 0 in 2D).
    std::vector<std::array<double, 3>> vertices;
    /// Cells: 2^dim vertex indices each, in deal.II's lexicographic order
    /// (vertex v at the corner with coordinate bits v&1, v&2, v&4 of the unit cell).
    std::vector<unsigned int> cells;
    std::vector<unsigned int> cell_material;
    /// Optional label of each cell in messages (e.g. the gmsh element tag); empty:
    /// the cell index is used.
    std::vector<std::uint64_t> cell_tag;
    /// Boundary faces: 2^(dim-1) vertex indices each (any cyclic order) and their ids.
    std::vector<unsigned int> faces;
    std::vector<unsigned int> face_boundary;

    unsigned int
    n_cell_vertices() const
    {
      return 1u << dim;
    }
    unsigned int
    n_face_vertices() const
    {
      return 1u << (dim - 1);
    }
    std::size_t
    n_cells() const
    {
      return cell_material.size();
    }
    std::size_t
    n_faces() const
    {
      return face_boundary.size();
    }
    /// "cell 12 (gmsh element 57) with vertices (0, 0), (1, 0), ..." for messages.
    std::string describe_cell(std::size_t c) const;
    /// Sorted distinct boundary ids / material ids.
    std::vector<unsigned int> boundary_ids() const;
    std::vector<unsigned int> material_ids() const;
    /// Bounding box of all vertices.
    void bounding_box(double lower[3], double upper[3]) const;
    /// Shortest cell edge (along the edges of the reference cell).
    double min_edge() const;
  };

  /// Structured box of n[0] x n[1] (x n[2]) cells, boundary ids 0..2dim-1 for the
  /// faces x-, x+, y-, y+, z-, z+ (as the solvers' box grid), material id 0.
  GridMesh make_box_mesh(unsigned int dim, const double lower[3], const double upper[3],
                         const std::vector<unsigned int> &n);

  /// Geometry check of every cell: the Jacobian determinant of the multilinear
  /// map at every corner must be > 0 (InputError naming the cell: "inverted" if
  /// all are negative, "degenerate" if they differ in sign or one is ~0).
  void check_cells(const GridMesh &mesh, const std::string &where);

  /// If every cell is an axis-aligned box (vertices at the corners within
  /// 1e-10 of the edge length), reorder each cell's vertices so that vertex 0 is
  /// the lower corner and the order is lexicographic (what the solvers' box
  /// kernel needs); otherwise InputError naming the first cell that is not.
  void normalise_boxes(GridMesh &mesh, const std::string &where);

  /// Every listed face must be a boundary face of the cells (a face of exactly
  /// one cell); InputError naming the first that is not.
  void check_faces(const GridMesh &mesh, const std::string &where);

  /// Write MSH 2.2 ASCII to path + ".part" and rename it to path.
  void write_msh(const GridMesh &mesh, const std::string &path);
  /// Read a MSH 2.2 ASCII grid file of dimension dim (first-order quads/hexes and
  /// their boundary faces; points ignored). InputError naming the file and line
  /// for anything else.
  GridMesh read_msh(const std::string &path, unsigned int dim);
} // namespace talus::io

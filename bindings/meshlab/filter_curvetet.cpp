// SPDX-License-Identifier: GPL-2.0-or-later
// MeshLab filter plugin for curvetet, over the C ABI (include/curvetet.h) only.
// GPL because it links MeshLab (see LICENSE.md in this folder).
#include "filter_curvetet.h"

#include <curvetet.h>

#include <QFileInfo>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <exception>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace {

struct SurfaceDeleter {
	void operator()(curvetet_surface *s) const { curvetet_surface_free(s); }
};
struct MeshDeleter {
	void operator()(curvetet_mesh *m) const { curvetet_mesh_free(m); }
};
using SurfacePtr = std::unique_ptr<curvetet_surface, SurfaceDeleter>;
using MeshPtr = std::unique_ptr<curvetet_mesh, MeshDeleter>;

// curvetet's progress (fraction, stage) to MeshLab's callback (percent, text). Never cancels:
// MeshLab's callbacks return true to mean "go on" and offer no cancel button for filters.
struct Progress {
	vcg::CallBackPos *cb = nullptr;
	int last = -1;
	std::string text;
};

int progressToMeshLab(void *user_data, double fraction, const char *stage)
{
	Progress *p = static_cast<Progress *>(user_data);
	if (p->cb == nullptr) return 0;
	int percent = int(std::floor(100.0 * std::min(1.0, std::max(0.0, fraction))));
	std::string text = std::string("curvetet: ") + (stage ? stage : "");
	if (percent != p->last || text != p->text) {
		p->last = percent;
		p->text = text;
		p->cb(percent, p->text.c_str());
	}
	return 0;
}

// Gmsh order of a 10-node tet: corners 0..3, then the mid nodes of edges (0,1), (1,2),
// (2,0), (3,0), (3,2), (3,1).
int midNode(int a, int b)
{
	if (a > b) std::swap(a, b);
	if (a == 0 && b == 1) return 4;
	if (a == 1 && b == 2) return 5;
	if (a == 0 && b == 2) return 6;
	if (a == 0 && b == 3) return 7;
	if (a == 2 && b == 3) return 8;
	return 9; // (1,3)
}

// The four faces of a positive tet, each oriented outward.
const int kTetFaces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

} // namespace

FilterCurveTetPlugin::FilterCurveTetPlugin()
{
	typeList << FP_CURVETET_TETRAHEDRALIZE;
	for (FilterIDType tt : types())
		actionList << new QAction(filterName(tt), this);
}

QString FilterCurveTetPlugin::pluginName() const
{
	return "FilterCurveTet";
}

QString FilterCurveTetPlugin::filterName(FilterIDType filterId) const
{
	switch (filterId) {
	case FP_CURVETET_TETRAHEDRALIZE: return "Tetrahedralize: curved quadratic (curvetet)";
	default: assert(0); return "";
	}
}

QString FilterCurveTetPlugin::filterInfo(FilterIDType filterId) const
{
	switch (filterId) {
	case FP_CURVETET_TETRAHEDRALIZE:
		return QString(
		    "Fills the current layer, a closed, manifold, outward-oriented triangle mesh, with a "
		    "quadratic (10-node) curved tetrahedral mesh using curvetet %1: the triangles are "
		    "curved first (edges sharper than <i>Feature angle</i> stay sharp), then an advancing "
		    "front fills the volume and every element is certified valid. The volume mesh is "
		    "written to <i>Output file</i> (.msh: Gmsh 4.1, element type 11; .vtu: VTK cell type "
		    "24); the quality summary goes to the log. A new layer shows the inside: the faces of "
		    "the tetrahedra on one side of the mid-plane through the bounding box centre "
		    "(normal to its longest side), each curved face drawn as four triangles (hide the "
		    "input layer to see it). The input layer is not changed and stays the current one. MeshLab stores coordinates in single precision: the volume "
		    "mesh's boundary corners are exactly the layer's vertices as MeshLab holds them.")
		    .arg(curvetet_version());
	default: assert(0); return "Unknown Filter";
	}
}

FilterCurveTetPlugin::FilterClass FilterCurveTetPlugin::getClass(QAction *a)
{
	switch (ID(a)) {
	case FP_CURVETET_TETRAHEDRALIZE: return MeshFilterInterface::Remeshing;
	default: assert(0); return MeshFilterInterface::Generic;
	}
}

MeshFilterInterface::FILTER_ARITY FilterCurveTetPlugin::filterArity(QAction *) const
{
	return SINGLE_MESH;
}

int FilterCurveTetPlugin::getPreConditions(QAction *) const
{
	return MeshModel::MM_FACENUMBER;
}

int FilterCurveTetPlugin::postCondition(QAction *) const
{
	// The input layer is not changed; the cut view is a new layer.
	return MeshModel::MM_NONE;
}

void FilterCurveTetPlugin::initParameterSet(QAction *action, MeshModel &m, RichParameterList &par)
{
	switch (ID(action)) {
	case FP_CURVETET_TETRAHEDRALIZE: {
		QString out = "curvetet_p2.msh";
		QFileInfo fi(m.fullName());
		if (!m.fullName().isEmpty())
			out = fi.absolutePath() + "/" + fi.completeBaseName() + "_p2.msh";
		par.addParam(RichFloat("alpha", 1.5f, "Search radius factor",
		                       "Candidate points are searched within alpha * h of the ideal point "
		                       "(h: the local target size). Default 1.5, the paper's."));
		par.addParam(RichFloat("featureAngle", 40.0f, "Feature angle (degrees)",
		                       "Edges whose triangles' normals differ by more than this angle are "
		                       "sharp features: kept sharp, and their mid nodes follow the feature "
		                       "curve. 0 < angle <= 180."));
		par.addParam(RichInt("smoothIterations", 0, "Smoothing iterations",
		                     "Taubin smoothing iterations applied to the layer's vertices before "
		                     "curving (0: none, the layer as it is). A raw marching-cubes surface "
		                     "from an image segmentation needs about 10: its sliver triangles "
		                     "leave the front stuck. The volume is then bounded by the smoothed "
		                     "surface, not the layer."));
		par.addParam(RichBool("optimize", true, "Optimize",
		                      "Improve the mesh quality (swaps, smoothing) and optimize the "
		                      "positions of the free quadratic nodes."));
		par.addParam(RichBool("thorough", false, "Thorough",
		                      "More high-order rounds where some element starts poor (CAD "
		                      "parts): two to three times that stage's work there, for fewer "
		                      "elements left between the worst one and a scaled Jacobian of 0.85."));
		par.addParam(RichSaveFile("outputFile", out, ".msh", "Output file (.msh or .vtu)",
		                          "Where the quadratic tetrahedral mesh is written: .msh (Gmsh 4.1) "
		                          "or .vtu (VTK XML)."));
		break;
	}
	default: assert(0);
	}
}

bool FilterCurveTetPlugin::applyFilter(QAction *action, MeshDocument &md,
                                       const RichParameterList &par, vcg::CallBackPos *cb)
{
	switch (ID(action)) {
	case FP_CURVETET_TETRAHEDRALIZE:
		try {
			return tetrahedralize(md, par, cb);
		} catch (const std::exception &e) {
			return fail(QString("curvetet filter: %1").arg(e.what()));
		}
	default: assert(0); return false;
	}
}

bool FilterCurveTetPlugin::fail(const QString &message)
{
	errorMessage = message;
	Log(GLLogStream::WARNING, qUtf8Printable(message));
	return false;
}

bool FilterCurveTetPlugin::tetrahedralize(MeshDocument &md, const RichParameterList &par,
                                          vcg::CallBackPos *cb)
{
	MeshModel *mm = md.mm();
	if (mm == nullptr) return fail("curvetet: no current layer");
	CMeshO &cm = mm->cm;

	const double alpha = par.getFloat("alpha");
	const double featureAngle = par.getFloat("featureAngle");
	const bool optimize = par.getBool("optimize");
	const bool thorough = par.getBool("thorough");
	const int smoothIterations = par.getInt("smoothIterations");
	if (smoothIterations < 0)
		return fail(QString("curvetet: smoothIterations must be 0 or more, not %1").arg(smoothIterations));
	const QString outputFile = par.getSaveFileName("outputFile");
	if (outputFile.isEmpty()) return fail("curvetet: no output file given (parameter outputFile)");

	// The layer's live vertices and faces (MeshLab may hold deleted ones), as curvetet's
	// arrays: vertices keep their order; coordinates are MeshLab's (single precision) values.
	std::vector<double> xyz;
	std::vector<uint32_t> tri3;
	std::vector<int64_t> remap(cm.vert.size(), -1);
	xyz.reserve(3 * size_t(cm.vn));
	uint32_t nv = 0;
	for (size_t i = 0; i < cm.vert.size(); ++i) {
		if (cm.vert[i].IsD()) continue;
		remap[i] = nv++;
		for (int k = 0; k < 3; ++k) xyz.push_back(double(cm.vert[i].cP()[k]));
	}
	tri3.reserve(3 * size_t(cm.fn));
	for (size_t i = 0; i < cm.face.size(); ++i) {
		const CFaceO &f = cm.face[i];
		if (f.IsD()) continue;
		for (int k = 0; k < 3; ++k) {
			int64_t v = remap[vcg::tri::Index(cm, f.cV(k))];
			if (v < 0) return fail("curvetet: a face of the layer uses a deleted vertex");
			tri3.push_back(uint32_t(v));
		}
	}
	if (tri3.empty()) return fail("curvetet: the current layer has no triangles");
	const size_t nt = tri3.size() / 3;
	Log("curvetet %s: %u vertices, %zu triangles from layer '%s'", curvetet_version(), nv, nt,
	    qUtf8Printable(mm->label()));

	if (cb) cb(0, "curvetet: curving the surface");
	if (smoothIterations > 0)
		Log("curvetet: %d Taubin smoothing iterations before curving", smoothIterations);
	curvetet_surface *raw_surface = nullptr;
	// (0 iterations: the same surface as curvetet_surface_from_linear, bit for bit.)
	curvetet_status st = curvetet_surface_from_linear_smoothed(
	    xyz.data(), nv, tri3.data(), nt, nullptr, featureAngle, uint32_t(smoothIterations),
	    &raw_surface);
	SurfacePtr surface(raw_surface);
	if (st != CURVETET_OK)
		return fail(QString("curvetet: %1: %2")
		                .arg(curvetet_error_name(st), QString::fromUtf8(curvetet_last_error_message())));
	for (size_t i = 0; i < curvetet_surface_num_warnings(surface.get()); ++i)
		Log(GLLogStream::WARNING, "curvetet: %s", curvetet_surface_warning(surface.get(), i));

	curvetet_options opt;
	curvetet_options_default(&opt);
	opt.alpha = alpha;
	opt.optimize = optimize ? 1 : 0;
	opt.thorough = thorough ? 1 : 0;
	Progress progress;
	progress.cb = cb;
	opt.progress = progressToMeshLab;
	opt.user_data = &progress;
	curvetet_mesh *raw_mesh = nullptr;
	st = curvetet_generate(surface.get(), &opt, &raw_mesh);
	MeshPtr mesh(raw_mesh);
	if (st != CURVETET_OK)
		return fail(QString("curvetet: %1: %2")
		                .arg(curvetet_error_name(st), QString::fromUtf8(curvetet_last_error_message())));

	const QByteArray path = outputFile.toUtf8();
	st = curvetet_mesh_write(mesh.get(), path.constData());
	if (st != CURVETET_OK)
		return fail(QString("curvetet: %1: %2")
		                .arg(curvetet_error_name(st), QString::fromUtf8(curvetet_last_error_message())));

	curvetet_quality q;
	q.struct_size = sizeof(q);
	st = curvetet_mesh_quality(mesh.get(), &q);
	if (st != CURVETET_OK)
		return fail(QString("curvetet: %1: %2")
		                .arg(curvetet_error_name(st), QString::fromUtf8(curvetet_last_error_message())));
	Log("curvetet: %llu quadratic tets, %zu nodes, written to %s", (unsigned long long)q.num_tets,
	    curvetet_mesh_num_nodes(mesh.get()), path.constData());
	Log("curvetet: min scaled Jacobian %.4f (certified >= %.4f), mean %.4f; max skewness %.4f; "
	    "dihedral angles %.2f..%.2f deg; invalid %llu",
	    q.min_scaled_jacobian, q.min_scaled_jacobian_certified, q.mean_scaled_jacobian,
	    q.max_skewness, q.min_dihedral_deg, q.max_dihedral_deg, (unsigned long long)q.num_invalid);

	// The cut view: the tets whose centroid lies below the mid-plane of the bounding box
	// (normal to its longest side); the faces of that set not shared by two of its tets.
	const size_t nn = curvetet_mesh_num_nodes(mesh.get());
	const double *nodes = curvetet_mesh_nodes(mesh.get());
	const size_t ntet = curvetet_mesh_num_tets(mesh.get());
	std::vector<uint32_t> tets(10 * ntet);
	st = curvetet_mesh_tets(mesh.get(), CURVETET_ORDER_GMSH, tets.data());
	if (st != CURVETET_OK || nodes == nullptr)
		return fail(QString("curvetet: %1: %2")
		                .arg(curvetet_error_name(st), QString::fromUtf8(curvetet_last_error_message())));
	double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
	for (size_t i = 0; i < nn; ++i)
		for (int k = 0; k < 3; ++k) {
			lo[k] = std::min(lo[k], nodes[3 * i + k]);
			hi[k] = std::max(hi[k], nodes[3 * i + k]);
		}
	int axis = 0;
	for (int k = 1; k < 3; ++k)
		if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
	const double mid = 0.5 * (lo[axis] + hi[axis]);
	std::map<std::array<uint32_t, 3>, std::pair<int, std::array<uint32_t, 6>>> faces;
	size_t kept = 0;
	for (size_t t = 0; t < ntet; ++t) {
		const uint32_t *tet = &tets[10 * t];
		double c = 0;
		for (int k = 0; k < 4; ++k) c += nodes[3 * size_t(tet[k]) + axis];
		if (c / 4 > mid) continue;
		++kept;
		for (const auto &fv : kTetFaces) {
			std::array<uint32_t, 6> f6 = {tet[fv[0]], tet[fv[1]], tet[fv[2]],
			                              tet[midNode(fv[0], fv[1])], tet[midNode(fv[1], fv[2])],
			                              tet[midNode(fv[2], fv[0])]};
			std::array<uint32_t, 3> key = {f6[0], f6[1], f6[2]};
			std::sort(key.begin(), key.end());
			auto it = faces.find(key);
			if (it == faces.end())
				faces.emplace(key, std::make_pair(1, f6));
			else
				++it->second.first;
		}
	}
	std::vector<int64_t> vmap(nn, -1);
	std::vector<uint32_t> cutNodes;
	std::vector<std::array<uint32_t, 3>> cutTris;
	for (const auto &kv : faces) {
		if (kv.second.first != 1) continue;
		const std::array<uint32_t, 6> &f = kv.second.second;
		uint32_t v[6];
		for (int k = 0; k < 6; ++k) {
			if (vmap[f[k]] < 0) {
				vmap[f[k]] = int64_t(cutNodes.size());
				cutNodes.push_back(f[k]);
			}
			v[k] = uint32_t(vmap[f[k]]);
		}
		// A 6-node triangle as four: three corner triangles and the middle one.
		cutTris.push_back({v[0], v[3], v[5]});
		cutTris.push_back({v[3], v[1], v[4]});
		cutTris.push_back({v[5], v[4], v[2]});
		cutTris.push_back({v[3], v[4], v[5]});
	}

	const char axisName[3] = {'x', 'y', 'z'};
	// A new layer, not made current: the input stays the current layer, so the filter can be
	// run again on it with other parameters.
	MeshModel *cut = md.addNewMesh("", mm->label() + " curvetet cut", false);
	if (cut == nullptr) return fail("curvetet: could not add the cut layer");
	CMeshO &cc = cut->cm;
	auto vi = vcg::tri::Allocator<CMeshO>::AddVertices(cc, cutNodes.size());
	for (size_t i = 0; i < cutNodes.size(); ++i, ++vi) {
		const double *p = &nodes[3 * size_t(cutNodes[i])];
		vi->P() = Point3m(Scalarm(p[0]), Scalarm(p[1]), Scalarm(p[2]));
	}
	auto fi = vcg::tri::Allocator<CMeshO>::AddFaces(cc, cutTris.size());
	for (size_t i = 0; i < cutTris.size(); ++i, ++fi)
		for (int k = 0; k < 3; ++k) fi->V(k) = &cc.vert[cutTris[i][k]];
	vcg::tri::UpdateBounding<CMeshO>::Box(cc);
	vcg::tri::UpdateNormal<CMeshO>::PerVertexNormalizedPerFaceNormalized(cc);
	Log("curvetet: layer '%s': %zu of %zu tets (centroid %c <= %g), %zu curved faces as %zu "
	    "triangles",
	    qUtf8Printable(cut->label()), kept, ntet, axisName[axis], mid, cutTris.size() / 4,
	    cutTris.size());
	if (cb) cb(100, "curvetet: done");
	return true;
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterCurveTetPlugin)

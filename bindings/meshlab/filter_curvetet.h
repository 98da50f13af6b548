// SPDX-License-Identifier: GPL-2.0-or-later
// MeshLab filter plugin for curvetet (see LICENSE.md in this folder: GPL, because it links
// MeshLab; the curvetet library it calls through include/curvetet.h keeps its own license).
#ifndef CURVETET_MESHLAB_FILTER_CURVETET_H
#define CURVETET_MESHLAB_FILTER_CURVETET_H

#include <common/interfaces.h>

// "Tetrahedralize: curved quadratic (curvetet)" (Filters > Remeshing, Simplification and
// Reconstruction): curves the current layer (a closed linear triangle mesh), fills it with
// certified-valid quadratic (10-node) tetrahedra through the curvetet C ABI, writes them to
// `outputFile` (.msh or .vtu), logs the quality summary and adds a layer with the cut view.
class FilterCurveTetPlugin : public QObject, public MeshFilterInterface
{
	Q_OBJECT
	MESHLAB_PLUGIN_IID_EXPORTER(MESH_FILTER_INTERFACE_IID)
	Q_INTERFACES(MeshFilterInterface)

public:
	enum { FP_CURVETET_TETRAHEDRALIZE };

	FilterCurveTetPlugin();

	QString pluginName() const override;
	QString filterName(FilterIDType filter) const override;
	QString filterInfo(FilterIDType filter) const override;
	FilterClass getClass(QAction *a) override;
	FILTER_ARITY filterArity(QAction *) const override;
	int getPreConditions(QAction *) const override;
	int postCondition(QAction *) const override;
	void initParameterSet(QAction *, MeshModel &m, RichParameterList &par) override;
	bool applyFilter(QAction *action, MeshDocument &md, const RichParameterList &par,
	                 vcg::CallBackPos *cb) override;

private:
	bool tetrahedralize(MeshDocument &md, const RichParameterList &par, vcg::CallBackPos *cb);
	bool fail(const QString &message);
};

#endif

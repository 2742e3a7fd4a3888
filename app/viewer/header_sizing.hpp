#pragma once
// Filling many rows of an item view whose columns size to their contents.
#include <QHeaderView>

#include <vector>

// A header's ResizeToContents sections measure their column over the view's rows (up to 1,000) at
// every changed cell, so filling n rows cost n × min(n, 1000) size hints: the Scene panel froze for
// 7 s at 1,000 parts when ghosting changed every part's opacity, the Probe dock for 4.6 s on a
// pixel of 1,024 fragments (a bug hunt). While one of these lives, those sections are Interactive;
// they return to ResizeToContents when it goes, which measures each column once.
class ContentSizedSectionsHeld {
 public:
  explicit ContentSizedSectionsHeld(QHeaderView* header) : header_(header) {
    for (int s = 0; s < header_->count(); ++s)
      if (header_->sectionResizeMode(s) == QHeaderView::ResizeToContents) {
        sections_.push_back(s);
        header_->setSectionResizeMode(s, QHeaderView::Interactive);
      }
  }
  ~ContentSizedSectionsHeld() {
    for (int s : sections_) header_->setSectionResizeMode(s, QHeaderView::ResizeToContents);
  }
  ContentSizedSectionsHeld(const ContentSizedSectionsHeld&) = delete;
  ContentSizedSectionsHeld& operator=(const ContentSizedSectionsHeld&) = delete;

 private:
  QHeaderView* header_;
  std::vector<int> sections_;
};
